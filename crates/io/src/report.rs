//! The report of a run: one self-contained HTML page (`report.html`) that a person reads, offline.
//!
//! [`render`] turns a [`ReportData`] (plain values: the model in a few lines, the sweep, how each
//! level ended, the FRF peaks, the figure files of the run, timings) into the page; it solves
//! nothing and reads only the figure files, which it embeds as base64 `data:` URIs (PNG and SVG
//! alike), so the page needs no other file, no network, no external script, style or font. A
//! Content-Security-Policy in the page forbids anything else.
//!
//! Sections: model (with its natural frequencies), sweep and levels, FRFs per output, peak table,
//! harmonics, hysteresis loops and slider velocities, timings; `stickslip compare` adds a test
//! comparison ([`with_comparison`]). Figures are sorted into sections
//! by the file names of [`crate::plot`] (`frf_<out>`, `harmonics_level<i>_<out>`,
//! `loop_level<i>_<el>`, `slider_level<i>_<el>`); other images go to a last section.
//!
//! A small inline script checks, on load, that every `<img>` decoded (`complete` and
//! `naturalWidth > 0`) and counts script errors (`window.onerror`, unhandled rejections and
//! `console.error` messages); it writes the result on the
//! `<body>` as `data-figures="loaded/total"` and `data-errors="count"` (both `"unchecked"` until
//! it runs), so that a headless browser's DOM dump verifies the page.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine as _;

use crate::output::LevelResult;
pub use crate::output::{BifurcationRecord, Peak};

/// The file name of the report in a run's output directory.
pub const REPORT_FILE: &str = "report.html";

/// Everything the report shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReportData {
    /// Page title: the study file's name.
    pub title: String,
    /// The study file as given (shown under the title).
    pub study_path: String,
    pub model: ModelSummary,
    pub sweep: SweepSummary,
    /// One entry per force level, in the study's order.
    pub levels: Vec<LevelSummary>,
    /// Largest FRF amplitude per level and output (see [`peaks`]).
    pub peaks: Vec<Peak>,
    /// Was the stability of every point computed?
    pub stability: bool,
    /// The bifurcations found, all levels: folds and branch points, and with the stability
    /// period doublings and Neimark-Sacker bifurcations.
    pub bifurcations: Vec<BifurcationRecord>,
    /// Files written by the run; the PNG and SVG ones are embedded, the others listed.
    pub files: Vec<PathBuf>,
    /// `(stage, seconds)`, in the order shown; empty when not measured.
    pub timings: Vec<(String, f64)>,
}

/// The analysed model in a few lines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelSummary {
    /// Where the model comes from (inline matrices, matrix files, a mesh).
    pub source: String,
    /// Number of DOFs of the model the harmonic balance runs on (after any reduction).
    pub n_dofs: usize,
    /// How the model was reduced; `None` when it was not.
    pub reduction: Option<String>,
    /// The viscous damping of the linear model.
    pub damping: String,
    pub joints: Vec<JointSummary>,
    /// Lowest natural frequencies of the analysed linear model `(K, M)`.
    pub natural_frequencies: NaturalFrequencies,
    /// Per mode of `natural_frequencies`, the share of the excitation that drives it:
    /// `(φ_rᵀF)² / FᵀM⁻¹F` with mass-normalised modes (the shares of all modes sum to 1; the
    /// modes a shaker test sees); empty when not computed.
    pub load_participation: Vec<f64>,
}

/// A joint: its name, where it acts, its law and the law's parameters (with units).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointSummary {
    pub name: String,
    pub placement: String,
    pub law: String,
    pub parameters: String,
}

/// Natural frequencies of the linear model, or why they are not shown.
#[derive(Clone, Debug, PartialEq)]
pub enum NaturalFrequencies {
    /// Lowest first (Hz).
    Computed(Vec<f64>),
    /// Not computed (e.g. a model too large for the dense eigensolution), or failed: the reason.
    NotAvailable(String),
}

impl Default for NaturalFrequencies {
    fn default() -> Self {
        NaturalFrequencies::NotAvailable("not computed".into())
    }
}

/// The sweep settings shared by every level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepSummary {
    /// Name of the exciting load.
    pub load: String,
    /// Force levels (N).
    pub levels_n: Vec<f64>,
    pub start_hz: f64,
    pub end_hz: f64,
    /// Harmonics N of the balance.
    pub harmonics: usize,
    /// Time samples per period of the AFT.
    pub samples: usize,
}

/// How one level's continuation went.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LevelSummary {
    /// Force level (N).
    pub level_n: f64,
    /// Converged points.
    pub points: usize,
    /// Did the branch cross the whole band?
    pub complete: bool,
    /// How the continuation ended, in words.
    pub ending: String,
}

/// Per level and output, the peak of the displacement FRF |X₁|/F: the located ones of a level
/// that has them ([`LevelResult::peaks`]), else the point of largest value (points whose FRF is
/// not a finite number are skipped; a level or output without any gives no entry).
pub fn peaks(levels: &[LevelResult]) -> Vec<Peak> {
    let mut peaks = Vec::new();
    for level in levels {
        if !level.peaks.is_empty() {
            peaks.extend(level.peaks.iter().cloned());
            continue;
        }
        let mut names: Vec<&str> = Vec::new();
        for p in &level.points {
            for o in &p.outputs {
                if !names.contains(&o.name.as_str()) {
                    names.push(&o.name);
                }
            }
        }
        for name in names {
            let best = level
                .points
                .iter()
                .filter_map(|p| Some((p, p.outputs.iter().find(|o| o.name == name)?)))
                .filter(|(_, o)| o.disp_frf.is_finite())
                .max_by(|a, b| a.1.disp_frf.total_cmp(&b.1.disp_frf));
            if let Some((p, o)) = best {
                peaks.push(Peak {
                    level_n: level.level_n,
                    output: name.to_string(),
                    frequency_hz: p.frequency_hz,
                    disp_frf: o.disp_frf,
                    accel_frf: o.accel_frf,
                    located: false,
                });
            }
        }
    }
    peaks
}

/// What went wrong making the report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// Render the report and write it to `dir/report.html`; returns its path.
pub fn write_report(dir: &Path, data: &ReportData) -> Result<PathBuf, ReportError> {
    let html = render(data)?;
    let path = dir.join(REPORT_FILE);
    std::fs::write(&path, html).map_err(|source| ReportError::Io { path: path.clone(), source })?;
    Ok(path)
}

/// Which section a figure goes to, from its file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Frf,
    Harmonics,
    Loop,
    Slider,
    Other,
}

/// An image of the run, read and ready to embed.
struct Figure {
    kind: Kind,
    /// Level index `i` of `..._level<i>_...` names.
    level: Option<usize>,
    /// The output or element the figure is about (from the file name).
    subject: String,
    file_name: String,
    data_uri: String,
}

fn mime(path: &Path) -> Option<&'static str> {
    match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "png" => Some("image/png"),
        "svg" => Some("image/svg+xml"),
        _ => None,
    }
}

/// Kind, level and subject from a file stem such as `loop_level2_joint`.
fn classify(stem: &str) -> (Kind, Option<usize>, String) {
    // The phase plot beside each FRF plot (`plot::plot_frf_phases`).
    if let Some(out) = stem.strip_prefix("frf_phase_") {
        return (Kind::Frf, None, format!("{out} (phase)"));
    }
    if let Some(out) = stem.strip_prefix("frf_") {
        return (Kind::Frf, None, out.to_string());
    }
    for (prefix, kind) in
        [("harmonics_level", Kind::Harmonics), ("loop_level", Kind::Loop), ("slider_level", Kind::Slider)]
    {
        if let Some(rest) = stem.strip_prefix(prefix) {
            if let Some((index, subject)) = rest.split_once('_') {
                if let Ok(i) = index.parse::<usize>() {
                    return (kind, Some(i), subject.to_string());
                }
            }
        }
    }
    (Kind::Other, None, stem.to_string())
}

fn read_figure(path: &Path, mime: &str) -> Result<Figure, ReportError> {
    let bytes = std::fs::read(path).map_err(|source| ReportError::Io { path: path.to_path_buf(), source })?;
    let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let stem = path.file_stem().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let (kind, level, subject) = classify(&stem);
    Ok(Figure { kind, level, subject, file_name, data_uri: format!("data:{mime};base64,{}", BASE64.encode(bytes)) })
}

/// Text for HTML content and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A number as people write it: plain for moderate magnitudes, exponent form otherwise.
pub fn number(v: f64) -> String {
    if v == 0.0 || (1e-3..1e5).contains(&v.abs()) {
        format!("{v}")
    } else if v.is_finite() {
        format!("{v:e}")
    } else {
        "—".to_string()
    }
}

/// A finite value with `digits` decimals, a dash otherwise.
fn fixed(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "—".to_string()
    }
}

/// A stage's time in seconds: to the microsecond below a second (the stages of a small
/// study take fractions of a millisecond), to 0.1 ms above.
fn duration(seconds: f64) -> String {
    fixed(seconds, if seconds < 1.0 { 6 } else { 4 })
}

/// A finite value to 4 significant digits (plain for moderate magnitudes, exponent form
/// otherwise), a dash otherwise.
fn sig(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        "—".to_string()
    } else if v == 0.0 {
        "0".to_string()
    } else if (1e-2..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

const STYLE: &str = "
body { font-family: sans-serif; max-width: 1200px; margin: 0 auto; padding: 0 1em 3em; color: #222; line-height: 1.4; }
h1 { margin-bottom: 0.2em; }
.sub { color: #555; margin-top: 0; }
nav a { margin-right: 1em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
th { background: #eee; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(480px, 1fr)); gap: 1em; }
.figures.wide { grid-template-columns: minmax(0, 1000px); }
figure { margin: 0; }
figure img { width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
.bad { color: #a00; }
";

/// Counts the images that decoded and the script errors, onto `<body>` and `#figure-check`.
const SCRIPT: &str = "
(function () {
  var errors = 0;
  function show() {
    if (document.body) document.body.setAttribute('data-errors', String(errors));
  }
  function count() { errors += 1; show(); }
  window.onerror = function () { count(); return false; };
  window.addEventListener('unhandledrejection', count);
  var consoleError = console.error;
  console.error = function () { count(); return consoleError.apply(console, arguments); };
  window.addEventListener('load', function () {
    var images = document.images, loaded = 0;
    for (var i = 0; i < images.length; i++) {
      if (images[i].complete && images[i].naturalWidth > 0) loaded += 1;
    }
    document.body.setAttribute('data-figures', loaded + '/' + images.length);
    show();
    var check = document.getElementById('figure-check');
    if (check) {
      check.textContent = loaded + ' of ' + images.length + ' figures shown' + (errors ? ', ' + errors + ' script error(s)' : '') + '.';
      if (loaded !== images.length || errors) check.className = 'bad';
    }
  });
})();
";

/// The report as one HTML page (figures read from `data.files` and embedded).
pub fn render(data: &ReportData) -> Result<String, ReportError> {
    let mut figures = Vec::new();
    let mut others = Vec::new();
    for path in &data.files {
        match mime(path) {
            Some(m) => figures.push(read_figure(path, m)?),
            None => others.push(path),
        }
    }
    let mut h = String::with_capacity(figures.iter().map(|f| f.data_uri.len() + 200).sum::<usize>() + 16_384);
    let title = escape(&data.title);
    // Writing into a String cannot fail: the `fmt::Result`s below are ignored.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{title} — stickslip report</title>\n<style>{STYLE}</style>\n<script>{SCRIPT}</script>\n</head>\n\
         <body data-figures=\"unchecked\" data-errors=\"unchecked\" data-expected-figures=\"{}\">\n\
         <h1>{title}</h1>\n<p class=\"sub\">Study file <code>{}</code>; stickslip {}. <span id=\"figure-check\"></span></p>\n",
        figures.len(),
        escape(&data.study_path),
        env!("CARGO_PKG_VERSION"),
    );
    let has = |k: &[Kind]| figures.iter().any(|f| k.contains(&f.kind));
    h.push_str("<nav>");
    let mut nav = vec![("model", "Model"), ("sweep", "Sweep"), ("frf", "FRFs"), ("peaks", "Peaks")];
    nav.push(("bifurcations", if data.stability { "Stability" } else { "Bifurcations" }));
    if has(&[Kind::Harmonics]) {
        nav.push(("harmonics", "Harmonics"));
    }
    if has(&[Kind::Loop, Kind::Slider]) {
        nav.push(("joints", "Hysteresis and slider velocity"));
    }
    if has(&[Kind::Other]) {
        nav.push(("other", "Other figures"));
    }
    nav.push(("timings", "Timings"));
    for (id, name) in nav {
        let _ = write!(h, "<a href=\"#{id}\">{name}</a>");
    }
    h.push_str("</nav>\n");

    model_section(&mut h, data);
    sweep_section(&mut h, data, &others);

    h.push_str("<section id=\"frf\">\n<h2>Frequency response functions</h2>\n");
    h.push_str("<p>Displacement FRF |X<sub>1</sub>|/F of each output against frequency, one curve per level.</p>\n");
    figure_grid(&mut h, true, figures.iter().filter(|f| f.kind == Kind::Frf), |f| format!("FRF of {}", f.subject));
    h.push_str("</section>\n");

    peak_section(&mut h, data);
    bifurcation_section(&mut h, data);

    let level_name = |i: Option<usize>| match i.and_then(|i| data.levels.get(i)) {
        Some(l) => format!("{} N", number(l.level_n)),
        None => format!("level {}", i.map_or_else(|| "?".to_string(), |i| i.to_string())),
    };
    if has(&[Kind::Harmonics]) {
        h.push_str("<section id=\"harmonics\">\n<h2>Harmonics</h2>\n");
        h.push_str(
            "<p>Amplitudes of harmonics 1..N of each output against frequency, one figure per level and output.</p>\n",
        );
        figure_grid(&mut h, false, figures.iter().filter(|f| f.kind == Kind::Harmonics), |f| {
            format!("Harmonics of {} at {}", f.subject, level_name(f.level))
        });
        h.push_str("</section>\n");
    }
    if has(&[Kind::Loop, Kind::Slider]) {
        h.push_str("<section id=\"joints\">\n<h2>Hysteresis loops and slider velocity</h2>\n");
        h.push_str("<p>Per level, at the point with time data where the first output's FRF is largest: each joint's force against its displacement, and its slider velocity over a period.</p>\n");
        figure_grid(&mut h, false, figures.iter().filter(|f| matches!(f.kind, Kind::Loop | Kind::Slider)), |f| {
            let what = if f.kind == Kind::Loop { "Hysteresis loop" } else { "Slider velocity" };
            format!("{what} of {} at {}", f.subject, level_name(f.level))
        });
        h.push_str("</section>\n");
    }
    if has(&[Kind::Other]) {
        h.push_str("<section id=\"other\">\n<h2>Other figures</h2>\n");
        figure_grid(&mut h, false, figures.iter().filter(|f| f.kind == Kind::Other), |f| f.subject.clone());
        h.push_str("</section>\n");
    }

    h.push_str("<section id=\"timings\">\n<h2>Timings</h2>\n");
    if data.timings.is_empty() {
        h.push_str("<p>Not measured.</p>\n");
    } else {
        h.push_str("<table>\n<tr><th>stage</th><th>time (s)</th></tr>\n");
        for (stage, seconds) in &data.timings {
            // A stage indented by spaces is a part of the one above it.
            let name = stage.trim_start();
            let indent = stage.len() - name.len();
            let _ = writeln!(
                h,
                "<tr><td style=\"padding-left:{}em\">{}</td><td class=\"num\">{}</td></tr>",
                0.5 + indent as f64,
                escape(name),
                duration(*seconds)
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("</section>\n</body>\n</html>\n");
    Ok(h)
}

fn model_section(h: &mut String, data: &ReportData) {
    let m = &data.model;
    h.push_str("<section id=\"model\">\n<h2>Model</h2>\n<table>\n");
    let mut row = |key: &str, value: String| {
        let _ = writeln!(h, "<tr><th>{key}</th><td>{value}</td></tr>");
    };
    row("source", escape(&m.source));
    row("DOFs analysed", m.n_dofs.to_string());
    row("reduced", m.reduction.as_deref().map_or_else(|| "no".to_string(), |r| format!("yes: {}", escape(r))));
    row("damping", escape(&m.damping));
    h.push_str("</table>\n");
    if m.joints.is_empty() {
        h.push_str("<p>No joints: the model is linear.</p>\n");
    } else {
        h.push_str("<h3>Joints</h3>\n<table>\n<tr><th>name</th><th>acts on</th><th>law</th><th>parameters</th></tr>\n");
        for j in &m.joints {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&j.name),
                escape(&j.placement),
                escape(&j.law),
                escape(&j.parameters)
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("<h3>Natural frequencies</h3>\n");
    match &m.natural_frequencies {
        NaturalFrequencies::Computed(f) if !f.is_empty() => {
            h.push_str("<p>Lowest modes of the linear model analysed (M, K without the joints' nonlinear forces: joints in the paper's form count as stuck).</p>\n");
            let driven = m.load_participation.len() == f.len();
            h.push_str("<table>\n<tr><th>mode</th><th>frequency (Hz)</th><th>in the band</th>");
            if driven {
                h.push_str("<th>driven by the load (share of (φ<sup>T</sup>F)²)</th>");
            }
            h.push_str("</tr>\n");
            let (lo, hi) = (data.sweep.start_hz.min(data.sweep.end_hz), data.sweep.start_hz.max(data.sweep.end_hz));
            for (r, f) in f.iter().enumerate() {
                let inside = if (lo..=hi).contains(f) { "yes" } else { "" };
                let _ = write!(
                    h,
                    "<tr><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{inside}</td>",
                    r + 1,
                    fixed(*f, 3)
                );
                if driven {
                    let _ = write!(h, "<td class=\"num\">{}</td>", sig(m.load_participation[r]));
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</table>\n");
        }
        NaturalFrequencies::Computed(_) => h.push_str("<p>None: the model has no DOFs.</p>\n"),
        NaturalFrequencies::NotAvailable(reason) => {
            let _ = writeln!(h, "<p>Not shown: {}.</p>", escape(reason));
        }
    }
    h.push_str("</section>\n");
}

fn sweep_section(h: &mut String, data: &ReportData, others: &[&PathBuf]) {
    let s = &data.sweep;
    h.push_str("<section id=\"sweep\">\n<h2>Sweep</h2>\n<table>\n");
    let levels: Vec<String> = s.levels_n.iter().map(|l| number(*l)).collect();
    let _ = writeln!(h, "<tr><th>load</th><td>{}</td></tr>", escape(&s.load));
    let _ = writeln!(h, "<tr><th>force levels (N)</th><td>{}</td></tr>", levels.join(", "));
    let _ = writeln!(h, "<tr><th>band (Hz)</th><td>{} to {}</td></tr>", number(s.start_hz), number(s.end_hz));
    let _ = writeln!(h, "<tr><th>harmonics</th><td>{}</td></tr>", s.harmonics);
    let _ = writeln!(h, "<tr><th>samples per period</th><td>{}</td></tr>", s.samples);
    h.push_str("</table>\n<h3>Levels</h3>\n<table>\n<tr><th>level (N)</th><th>points</th><th>continuation</th></tr>\n");
    for l in &data.levels {
        let class = if l.complete { "" } else { " class=\"bad\"" };
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td class=\"num\">{}</td><td{class}>{}</td></tr>",
            number(l.level_n),
            l.points,
            escape(&l.ending)
        );
    }
    h.push_str("</table>\n");
    if !others.is_empty() {
        h.push_str("<p>Data files: ");
        let names: Vec<String> = others
            .iter()
            .map(|p| {
                let name = escape(&p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default());
                format!("<a href=\"{name}\"><code>{name}</code></a>")
            })
            .collect();
        h.push_str(&names.join(", "));
        h.push_str(" (beside this page).</p>\n");
    }
    h.push_str("</section>\n");
}

fn peak_section(h: &mut String, data: &ReportData) {
    h.push_str("<section id=\"peaks\">\n<h2>Peaks</h2>\n");
    if data.peaks.is_empty() {
        h.push_str("<p>No converged points.</p>\n</section>\n");
        return;
    }
    h.push_str("<p>Per level and output, the converged point of largest displacement FRF.</p>\n<table>\n");
    h.push_str("<tr><th>level (N)</th><th>output</th><th>frequency (Hz)</th><th>|X<sub>1</sub>|/F (m/N)</th><th>&Omega;&sup2;|X<sub>1</sub>|/F (m/s&sup2;/N)</th></tr>\n");
    for p in &data.peaks {
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            number(p.level_n),
            escape(&p.output),
            fixed(p.frequency_hz, 3),
            sig(p.disp_frf),
            sig(p.accel_frf)
        );
    }
    h.push_str("</table>\n</section>\n");
}

fn bifurcation_section(h: &mut String, data: &ReportData) {
    let singular = "Folds (LP) and branch points (BP) come from the continuation's tangent and determinants at every \
                    point";
    if data.stability {
        h.push_str("<section id=\"bifurcations\">\n<h2>Stability and bifurcations</h2>\n");
        let _ = writeln!(
            h,
            "<p>Each point's stability comes from its Floquet exponents by Hill's method (frf.csv: <code>stable</code>, \
             <code>floquet_re_per_s</code>, <code>floquet_im_rad_per_s</code>); unstable branches are dashed in the FRF, \
             phase and harmonics plots, which mark the bifurcations. {singular}; period doublings (PD) and Neimark-Sacker bifurcations (NS) from a complex pair of \
             exponents crossing the imaginary axis (<code>bifurcations.csv</code>).</p>"
        );
    } else {
        h.push_str("<section id=\"bifurcations\">\n<h2>Bifurcations</h2>\n");
        let _ = writeln!(
            h,
            "<p>{singular} (<code>bifurcations.csv</code>). <code>stability = true</code> adds each point's \
             stability by Hill's method, and the period doublings and Neimark-Sacker bifurcations.</p>"
        );
    }
    if data.bifurcations.is_empty() {
        h.push_str("<p>No bifurcation on any branch.</p>\n</section>\n");
        return;
    }
    h.push_str("<table>\n<tr><th>level (N)</th><th>kind</th><th>frequency (Hz)</th><th>|X<sub>1</sub>| at the outputs (m)</th></tr>\n");
    for b in &data.bifurcations {
        let amplitudes: Vec<String> = b.amplitudes().map(|(o, a)| format!("{}: {}", escape(o), sig(a))).collect();
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td>{}{}</td><td class=\"num\">{}</td><td>{}</td></tr>",
            number(b.level_n),
            escape(&b.kind),
            if b.located { "" } else { " (not located: the point after it)" },
            fixed(b.frequency_hz, 4),
            amplitudes.join(", ")
        );
    }
    h.push_str("</table>\n</section>\n");
}

fn figure_grid<'a>(
    h: &mut String,
    wide: bool,
    figures: impl Iterator<Item = &'a Figure>,
    caption: impl Fn(&Figure) -> String,
) {
    let mut any = false;
    for f in figures {
        if !any {
            h.push_str(if wide { "<div class=\"figures wide\">\n" } else { "<div class=\"figures\">\n" });
            any = true;
        }
        let caption = escape(&caption(f));
        let _ = writeln!(
            h,
            "<figure><img src=\"{}\" alt=\"{caption}\"><figcaption>{caption} (<code>{}</code>)</figcaption></figure>",
            f.data_uri,
            escape(&f.file_name)
        );
    }
    if any {
        h.push_str("</div>\n");
    } else {
        h.push_str("<p>No figures.</p>\n");
    }
}

/// A test comparison (`stickslip compare`): measured FRFs against the run's, shown in the run's
/// report as its "Test comparison" section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    /// The measured files, as given.
    pub measured: Vec<String>,
    /// The overlay plots (PNG or SVG), embedded, with their captions.
    pub figures: Vec<(PathBuf, String)>,
    pub peaks: Vec<ComparedPeak>,
}

/// A measured resonance peak and the nearest simulated one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ComparedPeak {
    pub level_n: f64,
    pub output: String,
    /// Unit of the amplitudes (`m_per_N`, `m_s_per_N`, `m_s2_per_N`).
    pub unit: String,
    /// The measured file (stem).
    pub source: String,
    pub measured_frequency_hz: f64,
    pub measured_amplitude: f64,
    /// NaN where the simulated curve has no peak.
    pub simulated_frequency_hz: f64,
    pub simulated_amplitude: f64,
}

impl ComparedPeak {
    /// Simulated − measured frequency, relative to measured (%).
    pub fn frequency_error_pct(&self) -> f64 {
        100.0 * (self.simulated_frequency_hz - self.measured_frequency_hz) / self.measured_frequency_hz
    }

    /// Simulated − measured amplitude, relative to measured (%).
    pub fn amplitude_error_pct(&self) -> f64 {
        100.0 * (self.simulated_amplitude - self.measured_amplitude) / self.measured_amplitude
    }
}

const COMPARISON_BEGIN: &str = "<!-- test comparison -->\n";
const COMPARISON_END: &str = "<!-- end of test comparison -->\n";

/// The report page `page` with `comparison` as its "Test comparison" section, before the
/// timings (replacing the one an earlier comparison put there), linked from the navigation; the
/// page's count of expected figures follows. The page stays self-contained: the plots are
/// embedded as the run's are.
pub fn with_comparison(page: &str, comparison: &Comparison) -> Result<String, ReportError> {
    let mut section = String::from(COMPARISON_BEGIN);
    section.push_str("<section id=\"comparison\">\n<h2>Test comparison</h2>\n");
    let files: Vec<String> = comparison.measured.iter().map(|m| format!("<code>{}</code>", escape(m))).collect();
    let _ = writeln!(
        section,
        "<p>Measured FRFs ({}) against this run's, per level and output. Peaks: each measured resonance peak and the simulated peak nearest to it; errors are simulated − measured, relative to measured.</p>",
        files.join(", ")
    );
    section.push_str("<table>\n<tr><th>level (N)</th><th>output</th><th>unit</th><th>measured</th><th>f measured (Hz)</th><th>f simulated (Hz)</th><th>Δf (%)</th><th>peak measured</th><th>peak simulated</th><th>error (%)</th></tr>\n");
    for p in &comparison.peaks {
        let _ = writeln!(
            section,
            "<tr><td class=\"num\">{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            number(p.level_n),
            escape(&p.output),
            escape(&p.unit),
            escape(&p.source),
            fixed(p.measured_frequency_hz, 3),
            fixed(p.simulated_frequency_hz, 3),
            fixed(p.frequency_error_pct(), 2),
            sig(p.measured_amplitude),
            sig(p.simulated_amplitude),
            fixed(p.amplitude_error_pct(), 2),
        );
    }
    section.push_str("</table>\n");
    let mut figures = Vec::with_capacity(comparison.figures.len());
    for (path, caption) in &comparison.figures {
        if let Some(m) = mime(path) {
            figures.push(Figure { subject: caption.clone(), ..read_figure(path, m)? });
        }
    }
    figure_grid(&mut section, false, figures.iter(), |f| f.subject.clone());
    section.push_str("</section>\n");
    section.push_str(COMPARISON_END);

    // An earlier comparison is replaced.
    let mut page = match (page.find(COMPARISON_BEGIN), page.find(COMPARISON_END)) {
        (Some(a), Some(b)) if a < b => format!("{}{}", &page[..a], &page[b + COMPARISON_END.len()..]),
        _ => page.to_string(),
    };
    let at = page.find("<section id=\"timings\">").or_else(|| page.rfind("</body>")).unwrap_or(page.len());
    page.insert_str(at, &section);
    const TIMINGS_LINK: &str = "<a href=\"#timings\">";
    if !page.contains("<a href=\"#comparison\">") {
        if let Some(at) = page.find(TIMINGS_LINK) {
            page.insert_str(at, "<a href=\"#comparison\">Test comparison</a>");
        }
    }
    // The figure check expects every image of the page.
    const EXPECTED: &str = "data-expected-figures=\"";
    if let Some(from) = page.find(EXPECTED).map(|i| i + EXPECTED.len()) {
        if let Some(len) = page[from..].find('"') {
            let images = page.matches("<img ").count();
            page.replace_range(from..from + len, &images.to_string());
        }
    }
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::{OutputRecord, PointRecord};

    /// A 1×1 PNG (a white pixel) and a tiny SVG.
    const PNG: &[u8] = &[
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
        0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x90, 0x77, 0x53, 0xde, 0x00, 0x00, 0x00,
        0x0c, 0x49, 0x44, 0x41, 0x54, 0x08, 0xd7, 0x63, 0xf8, 0xff, 0xff, 0x3f, 0x00, 0x05, 0xfe, 0x02, 0xfe, 0xdc,
        0xcc, 0x59, 0xe7, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
    ];
    const SVG: &str =
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"><rect width=\"10\" height=\"10\"/></svg>";

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("stickslip-report-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn point(f: f64, outputs: &[(&str, f64)]) -> PointRecord {
        PointRecord {
            frequency_hz: f,
            outputs: outputs
                .iter()
                .map(|&(name, disp_frf)| OutputRecord {
                    name: name.into(),
                    disp_frf,
                    accel_frf: 2.0 * disp_frf,
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        }
    }

    fn data(dir: &Path, files: &[&str]) -> ReportData {
        let levels = vec![
            LevelResult {
                level_n: 100.0,
                points: vec![
                    point(200.0, &[("mass", 1e-6), ("a<b>&c", 3e-7)]),
                    point(238.25, &[("mass", 4.5e-5), ("a<b>&c", 2e-7)]),
                    point(260.0, &[("mass", f64::NAN), ("a<b>&c", 9.75e-6)]),
                ],
                peaks: vec![],
                bifurcations: vec![],
            },
            LevelResult { level_n: 1000.0, points: vec![], peaks: vec![], bifurcations: vec![] },
        ];
        ReportData {
            title: "study <1> & \"two\".toml".into(),
            study_path: "dir/study.toml".into(),
            model: ModelSummary {
                source: "inline matrices".into(),
                n_dofs: 1,
                reduction: None,
                damping: "Rayleigh".into(),
                joints: vec![JointSummary {
                    name: "joint<&>".into(),
                    placement: "DOF M and the ground".into(),
                    law: "Jenkins".into(),
                    parameters: "threshold 1000 N".into(),
                }],
                natural_frequencies: NaturalFrequencies::Computed(vec![238.2052, 1234.5]),
                load_participation: vec![0.75, 0.25],
            },
            sweep: SweepSummary {
                load: "shaker".into(),
                levels_n: vec![100.0, 1000.0],
                start_hz: 150.0,
                end_hz: 350.0,
                harmonics: 7,
                samples: 300,
            },
            levels: vec![
                LevelSummary { level_n: 100.0, points: 3, complete: true, ending: "reached the end".into() },
                LevelSummary { level_n: 1000.0, points: 0, complete: false, ending: "no convergence <here>".into() },
            ],
            peaks: peaks(&levels),
            stability: false,
            bifurcations: vec![],
            files: files.iter().map(|f| dir.join(f)).collect(),
            timings: vec![("sweep".into(), 1.23456), ("  located peaks".into(), 0.000612345)],
        }
    }

    #[test]
    fn every_figure_is_embedded_as_a_data_uri_in_its_section() {
        let dir = scratch("figures");
        let names = ["frf_mass.png", "harmonics_level0_mass.svg", "loop_level0_joint.png", "slider_level0_joint.png"];
        for n in names {
            if n.ends_with(".svg") {
                std::fs::write(dir.join(n), SVG).unwrap();
            } else {
                std::fs::write(dir.join(n), PNG).unwrap();
            }
        }
        std::fs::write(dir.join("frf.csv"), "x\n").unwrap();
        let mut files = vec!["frf.csv"];
        files.extend(names);
        let html = render(&data(&dir, &files)).unwrap();
        let png = format!("src=\"data:image/png;base64,{}\"", BASE64.encode(PNG));
        let svg = format!("src=\"data:image/svg+xml;base64,{}\"", BASE64.encode(SVG));
        assert_eq!(html.matches(&png).count(), 3);
        assert_eq!(html.matches(&svg).count(), 1);
        assert_eq!(html.matches("<img ").count(), 4);
        assert!(html.contains("data-expected-figures=\"4\""));
        // Nothing is fetched: no external reference, and a policy that forbids any.
        assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
        assert!(html.contains("default-src 'none'; img-src data:"));
        // Each figure in its section, captioned with its level in newtons.
        let at = |s: &str| html.find(s).unwrap_or_else(|| panic!("{s} missing"));
        assert!(at("id=\"frf\"") < at("frf_mass.png") && at("frf_mass.png") < at("id=\"peaks\""));
        assert!(at("id=\"harmonics\"") < at("harmonics_level0_mass.svg"));
        assert!(
            at("id=\"joints\"") < at("loop_level0_joint.png") && at("loop_level0_joint.png") < at("id=\"timings\"")
        );
        assert!(html.contains("Hysteresis loop of joint at 100 N"));
        assert!(html.contains("Slider velocity of joint at 100 N"));
        // The data file is listed, not embedded.
        assert!(html.contains("<a href=\"frf.csv\">"));
        // The check script and the attributes it fills.
        assert!(html.contains("data-figures=\"unchecked\" data-errors=\"unchecked\""));
        assert!(html.contains("naturalWidth > 0") && html.contains("window.onerror"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_folds_are_tabled_with_or_without_the_stability() {
        let dir = scratch("bifurcations");
        let mut data = data(&dir, &[]);
        let fold = BifurcationRecord {
            level_n: 100.0,
            kind: "fold".into(),
            frequency_hz: 241.25,
            harmonics: vec![("mass".into(), vec![(0.0, 0.0), (2.5e-4, -1.2)])],
            exponent_im: 0.0,
            located: true,
        };
        let html = render(&data).unwrap();
        assert!(html.contains("<a href=\"#bifurcations\">Bifurcations</a>") && html.contains("<h2>Bifurcations</h2>"));
        assert!(html.contains("No bifurcation on any branch."));
        data.bifurcations = vec![fold];
        let html = render(&data).unwrap();
        assert!(html.contains("<td>fold</td><td class=\"num\">241.2500</td><td>mass: 2.500e-4</td>"));
        assert!(!html.contains("Floquet exponents by Hill's method"));
        data.stability = true;
        let html = render(&data).unwrap();
        assert!(html.contains("<h2>Stability and bifurcations</h2>") && html.contains("<td>fold</td>"));
        assert!(html.contains("Floquet exponents by Hill's method"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_peak_table_has_the_largest_finite_frf_of_each_level_and_output() {
        let dir = scratch("peaks");
        let d = data(&dir, &[]);
        // NaN skipped; the empty level gives no row.
        assert_eq!(d.peaks.len(), 2);
        assert_eq!(
            (d.peaks[0].output.as_str(), d.peaks[0].frequency_hz, d.peaks[0].disp_frf),
            ("mass", 238.25, 4.5e-5)
        );
        assert_eq!(
            (d.peaks[1].output.as_str(), d.peaks[1].frequency_hz, d.peaks[1].disp_frf),
            ("a<b>&c", 260.0, 9.75e-6)
        );
        let html = render(&d).unwrap();
        let table = &html[html.find("id=\"peaks\"").unwrap()..html.find("id=\"harmonics\"").unwrap_or(html.len())];
        for value in ["238.250", "4.500e-5", "9.000e-5", "260.000", "9.750e-6", "1.950e-5"] {
            assert!(table.contains(value), "{value} not in the peak table");
        }
        // Natural frequencies, the level table, timings.
        assert!(html.contains("238.205") && html.contains("1234.500"));
        // The share of the load each mode takes, beside its frequency.
        assert!(html.contains("<td class=\"num\">238.205</td><td>yes</td><td class=\"num\">0.7500</td>"), "{html}");
        assert!(html.contains("<td class=\"num\">1000</td><td class=\"num\">0</td><td class=\"bad\">"));
        // Stage times to 0.1 ms above a second, to the microsecond below.
        assert!(html.contains("1.2346") && html.contains("0.000612"));
        assert!(html.contains("No figures."));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn names_are_escaped_everywhere() {
        let dir = scratch("escape");
        let name = "frf_a<b>&c.png";
        std::fs::write(dir.join(name), PNG).unwrap();
        let html = render(&data(&dir, &[name])).unwrap();
        assert!(html.contains("<title>study &lt;1&gt; &amp; &quot;two&quot;.toml — stickslip report</title>"));
        assert!(html.contains("<h1>study &lt;1&gt; &amp; &quot;two&quot;.toml</h1>"));
        assert!(html.contains("<td>joint&lt;&amp;&gt;</td>"));
        assert!(html.contains("<td>a&lt;b&gt;&amp;c</td>"));
        assert!(html.contains("no convergence &lt;here&gt;"));
        assert!(html.contains("alt=\"FRF of a&lt;b&gt;&amp;c\""));
        assert!(html.contains("<code>frf_a&lt;b&gt;&amp;c.png</code>"));
        for raw in ["a<b>", "<1>", "joint<", "<here>"] {
            assert!(!html.contains(raw), "{raw} unescaped");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_missing_figure_is_an_error_naming_it() {
        let dir = scratch("missing");
        let err = render(&data(&dir, &["frf_gone.png"])).unwrap_err();
        assert!(err.to_string().contains("frf_gone.png"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_test_comparison_joins_the_report_once_with_its_figures() {
        let dir = scratch("comparison");
        let plot = dir.join("compare_level0_mass_accel.png");
        std::fs::write(&plot, PNG).unwrap();
        let page = render(&ReportData { title: "t".into(), ..Default::default() }).unwrap();
        assert!(page.contains("data-expected-figures=\"0\""));
        let comparison = Comparison {
            measured: vec!["test.uff".into()],
            figures: vec![(plot, "mass at 70 N, acceleration".into())],
            peaks: vec![ComparedPeak {
                level_n: 70.0,
                output: "mass".into(),
                unit: "m_s2_per_N".into(),
                source: "test".into(),
                measured_frequency_hz: 238.0,
                measured_amplitude: 1.0,
                simulated_frequency_hz: 237.5,
                simulated_amplitude: 1.1,
            }],
        };
        let once = with_comparison(&page, &comparison).unwrap();
        // A second comparison replaces the first.
        assert_eq!(with_comparison(&once, &comparison).unwrap(), once);
        assert_eq!(once.matches("<h2>Test comparison</h2>").count(), 1);
        assert_eq!(once.matches("<a href=\"#comparison\">").count(), 1);
        assert!(once.contains("data-expected-figures=\"1\"") && once.contains("data:image/png;base64,"));
        // Errors relative to measured: −0.21 % in frequency, +10 % in amplitude.
        assert!(once.contains("<td class=\"num\">-0.21</td>") && once.contains("<td class=\"num\">10.00</td>"));
        assert!(once.find("id=\"comparison\"").unwrap() < once.find("id=\"timings\"").unwrap());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn numbers_without_a_value_are_dashes_and_classification_reads_plot_names() {
        assert_eq!(number(f64::NAN), "—");
        assert_eq!(number(8.11e6), "8.11e6");
        assert_eq!(number(1000.0), "1000");
        assert_eq!(fixed(f64::INFINITY, 2), "—");
        assert_eq!(
            (sig(2.82864), sig(0.600521), sig(-1.26714e-6), sig(0.0)),
            ("2.829".into(), "0.6005".into(), "-1.267e-6".into(), "0".into())
        );
        assert_eq!(classify("loop_level12_a_b"), (Kind::Loop, Some(12), "a_b".into()));
        assert_eq!(classify("harmonics_levelx_m"), (Kind::Other, None, "harmonics_levelx_m".into()));
        assert_eq!(classify("frf_tip"), (Kind::Frf, None, "tip".into()));
        assert_eq!(classify("frf_phase_tip"), (Kind::Frf, None, "tip (phase)".into()));
    }
}
