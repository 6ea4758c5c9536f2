//! Plots of results with plotters, as PNG or SVG (chosen by the file extension):
//! - [`plot_frf`]: FRF amplitude (log scale) against frequency in Hz, one curve per force level;
//! - [`plot_harmonics`]: amplitude of harmonics 1..N against frequency for one level (the paper's
//!   Fig. 21 view of where odd harmonics rise);
//! - [`plot_hysteresis`]: force against displacement of one element over a period;
//! - [`plot_slider_velocity`]: slider velocity v_P over a period (paper Eq. 33, Fig. 17);
//! - [`plot_joint_sides`]: velocities of a joint's two sides over two periods of a snapshot
//!   (the paper's Figs. 22-23: blade top P and envelope contact B);
//! - [`plot_frf_phase`]: phase of the first harmonic (degrees) against frequency, beside the
//!   FRF amplitude plot;
//! - [`plot_time_records`]: channels of one unit of a time record against time (`timesim`);
//! - [`plot_frf_set`]: amplitude and phase of extracted FRFs (`extract`);
//! - [`plot_comparison`]: measured against simulated FRF amplitudes (`compare`).
//!
//! SVG keeps text as text and needs no font; PNG rasterises labels with a system font found
//! through fontconfig (on Debian, the package fonts-dejavu-core provides one).

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use rayon::prelude::*;

use crate::output::{
    BifurcationRecord, ElementRecord, JointSides, LevelResult, OutputError, PointRecord, SnapshotResult,
};
use crate::records::{FrfSet, TimeRecords};
use crate::study::PlotFormat;

const SIZE: (u32, u32) = (1000, 650);
const FONT: &str = "sans-serif";
/// Decades shown below the largest value on a log axis.
const LOG_DECADES: i32 = 9;

/// Largest magnitude of an axis end. plotters steps through an axis to place its ticks: an
/// infinite end (1e308 × 1.5 on a log axis, or the span of ±1e308 on a linear one) never
/// ends that loop, and neither does a range too narrow for its magnitude to be stepped in f64.
const AXIS_LIMIT: f64 = 1e300;
/// Most decades a log axis spans (the tick loop of plotters counts decades).
const LOG_AXIS_DECADES: f64 = 30.0;

/// A finite linear axis range for data in `[lo, hi]`: ends clipped to ±1e300, the width at
/// least 1e-9 of the magnitude (data outside is clipped by the chart, not drawn at infinity).
pub fn linear_axis(lo: f64, hi: f64) -> Range<f64> {
    let clip = |v: f64| if v.is_nan() { 0.0 } else { v.clamp(-AXIS_LIMIT, AXIS_LIMIT) };
    let (lo, hi) = (clip(lo.min(hi)), clip(hi.max(lo)));
    let magnitude = lo.abs().max(hi.abs());
    let min_width = if magnitude > 0.0 { 1e-9 * magnitude } else { 1.0 };
    if hi - lo >= min_width {
        return lo..hi;
    }
    let mid = 0.5 * (lo + hi);
    mid - min_width..mid + min_width
}

/// A finite positive log axis range for positive data in `[lo, hi]`, with a margin of a
/// factor 1.5 each side: the top clipped to 1e300, the bottom at most 30 decades below it.
pub fn log_axis(lo: f64, hi: f64) -> Range<f64> {
    let hi = if hi.is_finite() && hi > 0.0 { hi.clamp(f64::MIN_POSITIVE, AXIS_LIMIT) } else { 1.0 };
    let floor = (hi * 10f64.powf(-LOG_AXIS_DECADES)).max(f64::MIN_POSITIVE);
    let lo = if lo.is_finite() && lo > 0.0 { lo.clamp(floor, hi) } else { floor };
    lo / 1.5..hi * 1.5
}

/// One curve: a label and its points, drawn dashed where `dashed` is true (per point; empty
/// for a solid curve): unstable stretches of a branch, or a prediction beside a computation.
struct Curve {
    label: String,
    points: Vec<(f64, f64)>,
    dashed: Vec<bool>,
}

/// A labelled point drawn on a chart (a bifurcation).
struct Marker {
    x: f64,
    y: f64,
    label: String,
}

/// A chart of curves, linear x, linear or log y.
struct Chart {
    title: String,
    x_label: String,
    y_label: String,
    log_y: bool,
    curves: Vec<Curve>,
    markers: Vec<Marker>,
}

impl Chart {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        // Log axes only take positive values, and values more than LOG_DECADES decades below
        // the largest are round-off (e.g. even harmonics of a symmetric response, ~1e-20 of
        // the first): both are left out rather than drawn at an arbitrary floor or stretching
        // the axis over noise.
        let largest =
            self.curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)).filter(|y| y.is_finite()).fold(0.0, f64::max);
        let floor = largest * 10f64.powi(-LOG_DECADES);
        let keep = move |&(_, y): &(f64, f64)| y.is_finite() && (!self.log_y || (y > 0.0 && y >= floor));
        let all: Vec<(f64, f64)> = self.curves.iter().flat_map(|c| c.points.iter().copied().filter(keep)).collect();
        // Nothing drawable (e.g. an output the excitation does not reach, zero on a log axis):
        // an empty chart that says so, rather than no file.
        let empty = all.is_empty();
        let (mut x0, mut x1) = if empty {
            min_max(self.curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)).filter(|x| x.is_finite()))
        } else {
            min_max(all.iter().map(|p| p.0))
        };
        if !x0.is_finite() {
            (x0, x1) = (0.0, 1.0);
        }
        let (mut y0, mut y1) = if empty { (1e-12, 1.0) } else { min_max(all.iter().map(|p| p.1)) };
        let title = if empty {
            format!("{} (no {}values to draw)", self.title, if self.log_y { "positive " } else { "finite " })
        } else {
            self.title.clone()
        };
        if x1 <= x0 {
            (x0, x1) = (x0 - 0.5 * x0.abs().max(1.0), x1 + 0.5 * x1.abs().max(1.0));
        }
        // Axis ends stay finite (see `AXIS_LIMIT`): finite data only is kept, but its span or
        // padding may overflow.
        if self.log_y {
            let x = linear_axis(x0, x1);
            (x0, x1) = (x.start, x.end);
        }
        let mut chart = ChartBuilder::on(&root);
        chart.caption(&title, (FONT, 22)).margin(15).x_label_area_size(45).y_label_area_size(85);
        if self.log_y {
            let y = log_axis(y0, y1);
            (y0, y1) = (y.start, y.end);
            let mut chart = chart.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(e)?;
            let label = move |y: &f64| log_tick(*y, y0, y1);
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .y_label_formatter(&label)
                .label_style((FONT, 15))
                .draw()
                .map_err(e)?;
            self.draw_curves(&mut chart, keep).map_err(e)?;
        } else {
            // Loops and signals: a margin on both axes so that the curve does not run along
            // the frame (FRFs keep their band as the x range).
            let pad = 0.05 * (y1 - y0).max(1e-3 * y0.abs().max(y1.abs())).max(f64::MIN_POSITIVE);
            (y0, y1) = (y0 - pad, y1 + pad);
            let pad = 0.03 * (x1 - x0);
            (x0, x1) = (x0 - pad, x1 + pad);
            let (x, y) = (linear_axis(x0, x1), linear_axis(y0, y1));
            (x0, x1, y0, y1) = (x.start, x.end, y.start, y.end);
            let mut chart = chart.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .x_label_formatter(&|x| tick(*x, x1 - x0))
                .y_label_formatter(&|y| tick(*y, y1 - y0))
                .label_style((FONT, 15))
                .draw()
                .map_err(e)?;
            self.draw_curves(&mut chart, keep).map_err(e)?;
        }
        root.present().map_err(e)
    }

    /// The curves, one colour each, dashed where unstable, their legend, and the markers.
    fn draw_curves<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(
        &self,
        chart: &mut ChartContext<'a, DB, CT>,
        keep: impl Fn(&(f64, f64)) -> bool + Copy,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        for (i, c) in self.curves.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let style = color.stroke_width(2);
            let kept: Vec<((f64, f64), bool)> = c
                .points
                .iter()
                .enumerate()
                .map(|(j, &p)| (p, c.dashed.get(j).copied().unwrap_or(false)))
                .filter(|(p, _)| keep(p))
                .collect();
            // Runs of equal stability, each sharing its first point with the previous run's
            // last so that the curve stays connected where the style changes.
            let mut start = 0;
            let mut labelled = false;
            while start < kept.len() || !labelled {
                let dashed = kept.get(start).is_some_and(|k| k.1);
                let mut end = start + 1;
                while end < kept.len() && kept[end].1 == dashed {
                    end += 1;
                }
                let run: Vec<(f64, f64)> =
                    kept[start.saturating_sub(1)..end.min(kept.len())].iter().map(|k| k.0).collect();
                let series = if dashed {
                    chart.draw_series(DashedLineSeries::new(run, 8, 6, style))?
                } else {
                    chart.draw_series(LineSeries::new(run, style))?
                };
                if !labelled {
                    series
                        .label(c.label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    labelled = true;
                }
                start = end;
            }
        }
        for m in self.markers.iter().filter(|m| keep(&(m.x, m.y))) {
            chart.draw_series(std::iter::once(
                EmptyElement::at((m.x, m.y))
                    + Circle::new((0, 0), 5, BLACK.stroke_width(2))
                    + Text::new(m.label.clone(), (7, -18), (FONT, 15)),
            ))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 15))
            .draw()
    }

    /// Render to `path`, PNG or SVG by its extension.
    fn render(&self, path: &Path) -> Result<(), OutputError> {
        let plot_error = |m: String| {
            let hint = if m.contains("Font loading error") {
                " (PNG labels need a system font: install one, e.g. the Debian package fonts-dejavu-core, or write SVG with plot_format = \"svg\")"
            } else {
                ""
            };
            OutputError::Plot(format!("{}: {m}{hint}", path.display()))
        };
        match path.extension().and_then(|x| x.to_str()) {
            Some("svg") => self.draw(SVGBackend::new(path, SIZE).into_drawing_area()).map_err(plot_error),
            Some("png") => self.draw(BitMapBackend::new(path, SIZE).into_drawing_area()).map_err(plot_error),
            _ => Err(plot_error("the plot file name must end in .png or .svg".into())),
        }
    }
}

/// The label of the tick at `y` of a log axis from `y0` to `y1`. Where the axis holds three
/// decade ticks or more, the decades only (1e-7, 1e-6, ...): the ticks in between (2e-7, 3e-7,
/// ...) would crowd it. Where it holds fewer (a resonance seen over a decade or two), the
/// decades alone would leave one or two labels to read values by: the ticks at 1, 2 and 5 of
/// each decade are labelled too, and at 3 where there is at most one decade tick.
fn log_tick(y: f64, y0: f64, y1: f64) -> String {
    let exponent = y.log10();
    let decade = (exponent - exponent.round()).abs() <= 1e-9;
    let decades_inside = (y1.log10() + 1e-9).floor() - (y0.log10() - 1e-9).ceil() + 1.0;
    let mantissa = y / 10f64.powf(exponent.floor());
    let labelled: &[f64] = if decades_inside < 2.0 { &[2.0, 3.0, 5.0] } else { &[2.0, 5.0] };
    let readable = labelled.iter().any(|m| (mantissa - m).abs() <= 1e-6 * m);
    if decade || (decades_inside < 3.0 && readable) {
        format!("{y:.0e}")
    } else {
        String::new()
    }
}

/// A tick label: plain decimals for moderate magnitudes, exponent form otherwise; a tick within
/// round-off of zero on an axis of width `span` is 0 (the tick positions are computed in
/// floating point: "-1.39e-17" appeared on slider-velocity plots).
fn tick(v: f64, span: f64) -> String {
    let v = if v.abs() <= 1e-9 * span.abs() { 0.0 } else { v };
    if v == 0.0 || (1e-2..1e5).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
}

fn output_index(p: &PointRecord, output: &str) -> Result<usize, OutputError> {
    p.outputs.iter().position(|o| o.name == output).ok_or_else(|| {
        let known: Vec<&str> = p.outputs.iter().map(|o| o.name.as_str()).collect();
        OutputError::Plot(format!("no output named {output:?} (outputs are: {})", known.join(", ")))
    })
}

fn element_index(p: &PointRecord, element: &str) -> Result<usize, OutputError> {
    p.elements.iter().position(|e| e.name == element).ok_or_else(|| {
        let known: Vec<&str> = p.elements.iter().map(|e| e.name.as_str()).collect();
        OutputError::Plot(format!("no element named {element:?} (elements are: {})", known.join(", ")))
    })
}

/// Displacement FRF |X₁|/F (m/N, log scale) of `output` against frequency (Hz), one curve per
/// level; dashed where the response is unstable and the bifurcations marked, when the study
/// computed stability.
pub fn plot_frf(path: &Path, levels: &[LevelResult], output: &str) -> Result<(), OutputError> {
    let mut curves = Vec::with_capacity(levels.len());
    let mut markers = Vec::new();
    for l in levels {
        let points = match l.points.first() {
            Some(p0) => {
                let o = output_index(p0, output)?;
                l.points.iter().map(|p| (p.frequency_hz, p.outputs[o].disp_frf)).collect()
            }
            None => Vec::new(),
        };
        curves.push(Curve {
            label: format!("{} N", l.level_n),
            points,
            dashed: l.points.iter().map(is_unstable).collect(),
        });
        for b in &l.bifurcations {
            if let Some((_, a)) = b.amplitudes().find(|(name, _)| *name == output) {
                markers.push(Marker { x: b.frequency_hz, y: a / l.level_n, label: bifurcation_symbol(&b.kind).into() });
            }
        }
    }
    Chart {
        title: format!(
            "FRF of {output} (displacement |X₁|/F, one curve per level{})",
            match dashed_note(&curves) {
                "" => String::new(),
                note => format!("; {note}"),
            }
        ),
        x_label: "Frequency (Hz)".into(),
        y_label: "Displacement / force (m/N)".into(),
        log_y: true,
        curves,
        markers,
    }
    .render(path)
}

/// Is this point known to be unstable?
fn is_unstable(p: &PointRecord) -> bool {
    p.stability.is_some_and(|s| !s.stable)
}

/// `" (unstable)"` for a point known to be unstable, else empty: the titles of the plots of
/// one point (hysteresis, slider velocity) say what the FRF plots show by dashes.
fn unstable_note(p: &PointRecord) -> &'static str {
    if is_unstable(p) {
        " (unstable)"
    } else {
        ""
    }
}

/// `"dashed: unstable"` when a curve has an unstable stretch, else empty: the titles of the
/// FRF, phase and harmonics plots say what the dashes mean.
fn dashed_note(curves: &[Curve]) -> &'static str {
    if curves.iter().any(|c| c.dashed.iter().any(|&u| u)) {
        "dashed: unstable"
    } else {
        ""
    }
}

/// The phase of a harmonic `(A_k, φ_k)` as the phase plot draws it: φ_k in degrees, wrapped
/// as [`crate::output::harmonics_from_coefficients`] gives it, in (−180, 180]. The curves' points and
/// the bifurcations' markers both go through here, so that a marker sits on its curve.
fn phase_degrees(h: (f64, f64)) -> f64 {
    h.1.to_degrees()
}

/// The harmonics `(A_k, φ_k)`, k = 0..=N, of `output` at bifurcation `b` (empty when the record
/// does not carry them).
fn bifurcation_harmonics<'b>(b: &'b BifurcationRecord, output: &str) -> &'b [(f64, f64)] {
    b.harmonics.iter().find(|(name, _)| name == output).map_or(&[], |(_, h)| h.as_slice())
}

/// The short mark of a bifurcation kind on plots (its name in full is in bifurcations.csv).
fn bifurcation_symbol(kind: &str) -> &'static str {
    match kind {
        "fold" => "LP",
        "branch point" => "BP",
        "period doubling" => "PD",
        "Neimark-Sacker" => "NS",
        _ => "?",
    }
}

/// One FRF plot per output, `dir/frf_<output>.<png|svg>`; returns the files written.
pub fn plot_frfs(dir: &Path, levels: &[LevelResult], format: PlotFormat) -> Result<Vec<PathBuf>, OutputError> {
    draw_all(per_output(dir, levels, format, "frf", plot_frf))
}

/// Every plot of a sweep's results: [`plot_frfs`], [`plot_frf_phases`] and
/// [`plot_level_details`], drawn side by side on the thread pool; returns the files written,
/// in that order.
pub fn plot_results(dir: &Path, levels: &[LevelResult], format: PlotFormat) -> Result<Vec<PathBuf>, OutputError> {
    let mut jobs = per_output(dir, levels, format, "frf", plot_frf);
    jobs.extend(per_output(dir, levels, format, "frf_phase", plot_frf_phase));
    jobs.extend(level_details(dir, levels, format));
    draw_all(jobs)
}

/// A plot to draw: its file and what draws it. The plots of a run depend on nothing but the
/// results, so they are drawn in parallel.
struct PlotJob<'a> {
    path: PathBuf,
    draw: DrawPlot<'a>,
}

/// What draws a plot into the file it is given.
type DrawPlot<'a> = Box<dyn Fn(&Path) -> Result<(), OutputError> + Send + Sync + 'a>;

impl<'a> PlotJob<'a> {
    fn new(path: PathBuf, draw: impl Fn(&Path) -> Result<(), OutputError> + Send + Sync + 'a) -> Self {
        PlotJob { path, draw: Box::new(draw) }
    }
}

/// Draw `jobs` on the thread pool (one thread with `--threads 1`); returns their files in the
/// order given.
fn draw_all(jobs: Vec<PlotJob<'_>>) -> Result<Vec<PathBuf>, OutputError> {
    jobs.par_iter().with_min_len(PLOTS_PER_THREAD).map(|job| (job.draw)(&job.path)).collect::<Result<(), _>>()?;
    Ok(jobs.into_iter().map(|job| job.path).collect())
}

/// Fewest plots a thread draws. Each thread that draws a PNG looks its font up through
/// fontconfig once (plotters 0.3.7 keeps fonts per thread: its process-wide cache is read but
/// the lookup runs all the same), which costs about as much as drawing two plots; a thread
/// joins in only for enough plots to pay for it.
const PLOTS_PER_THREAD: usize = 4;

/// A plot `plot(dir/<stem>_<output>.<ext>, levels, output)` for every output of the levels'
/// points.
fn per_output<'a>(
    dir: &Path,
    levels: &'a [LevelResult],
    format: PlotFormat,
    stem: &str,
    plot: fn(&Path, &[LevelResult], &str) -> Result<(), OutputError>,
) -> Vec<PlotJob<'a>> {
    let Some(first) = levels.iter().flat_map(|l| l.points.first()).next() else { return Vec::new() };
    first
        .outputs
        .iter()
        .map(|o| {
            let path = dir.join(format!("{stem}_{}.{}", o.name, format.extension()));
            let output = o.name.clone();
            PlotJob::new(path, move |path| plot(path, levels, &output))
        })
        .collect()
}

/// Amplitudes of harmonics 1..N (m, log scale) of `output` against frequency (Hz) for one level;
/// dashed where the response is unstable, and the level's bifurcations marked on every
/// harmonic that is not zero there.
pub fn plot_harmonics(path: &Path, level: &LevelResult, output: &str) -> Result<(), OutputError> {
    let Some(p0) = level.points.first() else {
        return Err(OutputError::Plot(format!("level {} N has no points to plot", level.level_n)));
    };
    let o = output_index(p0, output)?;
    let curves = harmonic_curves(level, o);
    // Each bifurcation on every harmonic's curve; the chart leaves out the markers of a
    // harmonic that is zero (or round-off) there, as it does the curves' points.
    let markers = level
        .bifurcations
        .iter()
        .flat_map(|b| {
            let h = bifurcation_harmonics(b, output);
            (1..h.len().min(curves.len() + 1)).map(move |k| Marker {
                x: b.frequency_hz,
                y: h[k].0,
                label: bifurcation_symbol(&b.kind).into(),
            })
        })
        .collect();
    Chart {
        title: match dashed_note(&curves) {
            "" => format!("Harmonics of {output} at {} N", level.level_n),
            note => format!("Harmonics of {output} at {} N ({note})", level.level_n),
        },
        x_label: "Frequency (Hz)".into(),
        y_label: "Amplitude (m)".into(),
        log_y: true,
        curves,
        markers,
    }
    .render(path)
}

/// The curves of harmonics 1..N of output `o`. A harmonic that is zero at every point (the
/// even harmonics of a half-wave symmetric response, which a balance of sliders pins at zero)
/// has no line on a log axis: its label says so, rather than leave a colour in the legend
/// without a line.
fn harmonic_curves(level: &LevelResult, o: usize) -> Vec<Curve> {
    let n = level.points.first().map_or(0, |p| p.outputs[o].harmonics.len().saturating_sub(1));
    (1..=n)
        .map(|k| {
            let points: Vec<(f64, f64)> =
                level.points.iter().map(|p| (p.frequency_hz, p.outputs[o].harmonics[k].0)).collect();
            let zero = points.iter().all(|&(_, a)| a == 0.0);
            Curve {
                label: if zero { format!("harmonic {k} (zero)") } else { format!("harmonic {k}") },
                points,
                dashed: level.points.iter().map(is_unstable).collect(),
            }
        })
        .collect()
}

/// Hysteresis loop of `element` at one point: force (N) against displacement (m), closed.
pub fn plot_hysteresis(path: &Path, level_n: f64, point: &PointRecord, element: &str) -> Result<(), OutputError> {
    let e = &point.elements[element_index(point, element)?];
    let mut points: Vec<(f64, f64)> = e.loop_u.iter().copied().zip(e.loop_force.iter().copied()).collect();
    if let Some(&p) = points.first() {
        points.push(p);
    }
    Chart {
        title: format!("Hysteresis of {element} at {:.4} Hz, {level_n} N{}", point.frequency_hz, unstable_note(point)),
        x_label: "Displacement (m)".into(),
        y_label: "Force (N)".into(),
        log_y: false,
        curves: vec![Curve { label: element.into(), points, dashed: Vec::new() }],
        markers: Vec::new(),
    }
    .render(path)
}

/// Slider velocity v_P (m/s, Eq. 33) of `element` over one period against time (ms).
pub fn plot_slider_velocity(path: &Path, level_n: f64, point: &PointRecord, element: &str) -> Result<(), OutputError> {
    let e = &point.elements[element_index(point, element)?];
    let n_t = e.slider_velocity.len();
    let period_ms = 1e3 / point.frequency_hz;
    let points = e.slider_velocity.iter().enumerate().map(|(j, &v)| (period_ms * j as f64 / n_t as f64, v)).collect();
    Chart {
        title: format!(
            "Slider velocity of {element} at {:.4} Hz, {level_n} N{}",
            point.frequency_hz,
            unstable_note(point)
        ),
        x_label: "Time (ms)".into(),
        y_label: "Velocity (m/s)".into(),
        log_y: false,
        curves: vec![Curve { label: element.into(), points, dashed: Vec::new() }],
        markers: Vec::new(),
    }
    .render(path)
}

/// Velocities (m/s) of the two sides of a joint over two periods (ms) of a snapshot: where they
/// coincide the joint sticks, where they part it slips (paper Figs. 22-23).
pub fn plot_joint_sides(path: &Path, snapshot: &SnapshotResult, sides: &JointSides) -> Result<(), OutputError> {
    let f = snapshot.point.frequency_hz;
    let two_periods = |v: &[f64]| -> Vec<(f64, f64)> {
        let n_t = v.len();
        let dt_ms = 1e3 / (f * n_t as f64);
        v.iter().chain(v).enumerate().map(|(j, &x)| (dt_ms * j as f64, x)).collect()
    };
    Chart {
        title: format!("{} at {f} Hz, {} N: velocities of its two sides", sides.joint, snapshot.level_n),
        x_label: "Time (ms)".into(),
        y_label: "Velocity (m/s)".into(),
        log_y: false,
        curves: vec![
            Curve {
                label: format!("{} = {} + slip velocity (Eq. 33)", sides.dof_a, sides.dof_b),
                points: two_periods(&sides.velocity_a),
                dashed: Vec::new(),
            },
            Curve { label: sides.dof_b.clone(), points: two_periods(&sides.velocity_b), dashed: Vec::new() },
        ],
        markers: Vec::new(),
    }
    .render(path)
}

/// Per level `i`: the harmonics of each output (`harmonics_level<i>_<out>`), and, at the point
/// with time data where the first output's FRF is largest (the resonance, as in the paper's
/// Fig. 17), each element's hysteresis loop (`loop_level<i>_<el>`) and slider velocity
/// (`slider_level<i>_<el>`): of every element direction when there are at most
/// [`DETAILED_ELEMENTS`], else of the [`DETAILED_ELEMENTS`] that dissipate most there (a
/// contact patch has hundreds; all of them are in the time data). Returns the files written.
pub fn plot_level_details(dir: &Path, levels: &[LevelResult], format: PlotFormat) -> Result<Vec<PathBuf>, OutputError> {
    draw_all(level_details(dir, levels, format))
}

/// Element directions whose loops and slider velocities [`plot_level_details`] draws per level
/// at most: the four joints of the paper's Harmony study twice over.
pub const DETAILED_ELEMENTS: usize = 8;

/// The plots of [`plot_level_details`].
fn level_details<'a>(dir: &Path, levels: &'a [LevelResult], format: PlotFormat) -> Vec<PlotJob<'a>> {
    let ext = format.extension();
    let mut jobs = Vec::new();
    for (i, level) in levels.iter().enumerate() {
        let Some(p0) = level.points.first() else { continue };
        for o in &p0.outputs {
            if o.harmonics.len() > 1 {
                let path = dir.join(format!("harmonics_level{i}_{}.{ext}", o.name));
                let output = o.name.as_str();
                jobs.push(PlotJob::new(path, move |path| plot_harmonics(path, level, output)));
            }
        }
        let resonance =
            level.points.iter().filter(|p| p.elements.iter().any(|e| !e.loop_u.is_empty())).max_by(|a, b| {
                let amplitude = |p: &PointRecord| p.outputs.first().map_or(0.0, |o| o.disp_frf);
                amplitude(a).total_cmp(&amplitude(b))
            });
        let Some(point) = resonance else { continue };
        let mut detailed: Vec<&ElementRecord> = point.elements.iter().filter(|e| !e.loop_u.is_empty()).collect();
        if detailed.len() > DETAILED_ELEMENTS {
            // Stable: among equal energies (a stuck patch) the first in the study's order.
            detailed.sort_by(|a, b| b.energy_j.total_cmp(&a.energy_j));
            detailed.truncate(DETAILED_ELEMENTS);
        }
        for e in detailed {
            let (level_n, element) = (level.level_n, e.name.as_str());
            let path = dir.join(format!("loop_level{i}_{element}.{ext}"));
            jobs.push(PlotJob::new(path, move |path| plot_hysteresis(path, level_n, point, element)));
            if !e.slider_velocity.is_empty() {
                let path = dir.join(format!("slider_level{i}_{element}.{ext}"));
                jobs.push(PlotJob::new(path, move |path| plot_slider_velocity(path, level_n, point, element)));
            }
        }
    }
    jobs
}

/// Phase of the first harmonic of `output` against the force, in degrees in (−180, 180],
/// against frequency (Hz), one curve per level: with `x = A₁ cos(Ωt + φ₁)` under
/// `F cos Ωt`, φ₁ (0 well below a resonance, −90° at it, −180° above); dashed where the
/// response is unstable and the bifurcations marked, as [`plot_frf`].
pub fn plot_frf_phase(path: &Path, levels: &[LevelResult], output: &str) -> Result<(), OutputError> {
    let mut curves = Vec::with_capacity(levels.len());
    let mut markers = Vec::new();
    for l in levels {
        let points = match l.points.first() {
            Some(p0) => {
                let o = output_index(p0, output)?;
                l.points
                    .iter()
                    .filter_map(|p| p.outputs[o].harmonics.get(1).map(|&h| (p.frequency_hz, phase_degrees(h))))
                    .collect()
            }
            None => Vec::new(),
        };
        curves.push(Curve {
            label: format!("{} N", l.level_n),
            points,
            dashed: l.points.iter().map(is_unstable).collect(),
        });
        for b in &l.bifurcations {
            if let Some(&h) = bifurcation_harmonics(b, output).get(1) {
                markers.push(Marker {
                    x: b.frequency_hz,
                    y: phase_degrees(h),
                    label: bifurcation_symbol(&b.kind).into(),
                });
            }
        }
    }
    Chart {
        title: format!(
            "Phase of {output} (harmonic 1 against the force, one curve per level{})",
            match dashed_note(&curves) {
                "" => String::new(),
                note => format!("; {note}"),
            }
        ),
        x_label: "Frequency (Hz)".into(),
        y_label: "Phase (degrees)".into(),
        log_y: false,
        curves,
        markers,
    }
    .render(path)
}

/// One phase plot per output, `dir/frf_phase_<output>.<png|svg>`, beside the amplitude plots of
/// [`plot_frfs`]; returns the files written.
pub fn plot_frf_phases(dir: &Path, levels: &[LevelResult], format: PlotFormat) -> Result<Vec<PathBuf>, OutputError> {
    draw_all(per_output(dir, levels, format, "frf_phase", plot_frf_phase))
}

/// Most points drawn per curve of a time record: a swept sine holds millions of samples, which
/// no plot shows apart; every k-th sample is drawn beyond this.
const MAX_TIME_POINTS: usize = 20_000;

/// The channels of `records` in `unit` (e.g. `m`) against time (s), one curve each; an error
/// naming the units there are when none is in `unit`.
pub fn plot_time_records(path: &Path, title: &str, records: &TimeRecords, unit: &str) -> Result<(), OutputError> {
    let stride = records.len().div_ceil(MAX_TIME_POINTS).max(1);
    let dt = 1.0 / records.sample_rate_hz;
    let curves: Vec<Curve> = records
        .channels
        .iter()
        .filter(|c| c.unit == unit)
        .map(|c| Curve {
            label: c.name.clone(),
            points: c
                .values
                .iter()
                .enumerate()
                .step_by(stride)
                .map(|(j, &v)| (records.start_s + j as f64 * dt, v))
                .collect(),
            dashed: Vec::new(),
        })
        .collect();
    if curves.is_empty() {
        let units: Vec<&str> = records.channels.iter().map(|c| c.unit.as_str()).collect();
        return Err(OutputError::Plot(format!(
            "{}: no channel in {unit} to plot (the units are {units:?})",
            records.source
        )));
    }
    Chart {
        title: title.into(),
        x_label: "Time (s)".into(),
        y_label: format!("{} ({})", quantity_of(unit), unit_text(unit)),
        log_y: false,
        curves,
        markers: Vec::new(),
    }
    .render(path)
}

/// What a value in `unit` is, for axis labels.
fn quantity_of(unit: &str) -> &'static str {
    match unit {
        "m" => "Displacement",
        "m_s" => "Velocity",
        "m_s2" => "Acceleration",
        "N" => "Force",
        _ => "Value",
    }
}

/// A unit as read on an axis: `m_s2_per_N` → `m/s² / N`.
fn unit_text(unit: &str) -> String {
    let (num, per) = match unit.split_once("_per_") {
        Some((n, d)) => (n, Some(d)),
        None => (unit, None),
    };
    let num = match num {
        "m_s" => "m/s",
        "m_s2" => "m/s²",
        other => other,
    };
    per.map_or_else(|| num.to_string(), |d| format!("{num} / {d}"))
}

/// The FRFs of `set`, per unit: amplitude (log scale) `<stem>_amp_<unit>` and phase (degrees)
/// `<stem>_phase_<unit>`, one curve per channel. Returns the files written.
pub fn plot_frf_set(dir: &Path, stem: &str, set: &FrfSet, format: PlotFormat) -> Result<Vec<PathBuf>, OutputError> {
    let mut units: Vec<&str> = Vec::new();
    for c in &set.curves {
        if !units.contains(&c.unit.as_str()) {
            units.push(&c.unit);
        }
    }
    let level = set.level_n.map_or_else(String::new, |l| format!(" at {l:.4} N"));
    let mut files = Vec::new();
    for unit in units {
        let of_unit: Vec<_> = set.curves.iter().filter(|c| c.unit == unit).collect();
        let curves = |value: &dyn Fn(num_complex::Complex64) -> f64| -> Vec<Curve> {
            of_unit
                .iter()
                .map(|c| Curve {
                    label: c.name.clone(),
                    points: set.frequency_hz.iter().zip(&c.values).map(|(&f, &v)| (f, value(v))).collect(),
                    dashed: Vec::new(),
                })
                .collect()
        };
        let path = dir.join(format!("{stem}_amp_{unit}.{}", format.extension()));
        Chart {
            title: format!("Extracted FRFs{level} (harmonic 1)"),
            x_label: "Frequency (Hz)".into(),
            y_label: format!("|FRF| ({})", unit_text(unit)),
            log_y: true,
            curves: curves(&|v| v.norm()),
            markers: Vec::new(),
        }
        .render(&path)?;
        files.push(path);
        // Amplitude-only curves have no phase to draw.
        if of_unit.iter().any(|c| c.has_phase) {
            let path = dir.join(format!("{stem}_phase_{unit}.{}", format.extension()));
            Chart {
                title: format!("Extracted FRFs{level}: phase against the reference"),
                x_label: "Frequency (Hz)".into(),
                y_label: "Phase (degrees)".into(),
                log_y: false,
                curves: curves(&|v| v.arg().to_degrees()),
                markers: Vec::new(),
            }
            .render(&path)?;
            files.push(path);
        }
    }
    Ok(files)
}

/// One measured FRF amplitude curve of [`plot_comparison`].
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredCurve {
    /// Where it comes from (a file stem).
    pub label: String,
    pub frequency_hz: Vec<f64>,
    pub amplitude: Vec<f64>,
}

/// Measured (markers) against simulated (line) FRF amplitudes of one quantity, in `unit`
/// (e.g. `m_s2_per_N`), on a log axis. The markers are drawn over the line and ringed, so that
/// measured points on the simulated curve stay visible.
pub fn plot_comparison(
    path: &Path,
    title: &str,
    unit: &str,
    simulated: &(Vec<f64>, Vec<f64>),
    measured: &[MeasuredCurve],
) -> Result<(), OutputError> {
    let plot_error = |m: String| OutputError::Plot(format!("{}: {m}", path.display()));
    match path.extension().and_then(|x| x.to_str()) {
        Some("svg") => {
            draw_comparison(SVGBackend::new(path, SIZE).into_drawing_area(), title, unit, simulated, measured)
                .map_err(plot_error)
        }
        Some("png") => {
            draw_comparison(BitMapBackend::new(path, SIZE).into_drawing_area(), title, unit, simulated, measured)
                .map_err(plot_error)
        }
        _ => Err(plot_error("the plot file name must end in .png or .svg".into())),
    }
}

fn draw_comparison<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    unit: &str,
    simulated: &(Vec<f64>, Vec<f64>),
    measured: &[MeasuredCurve],
) -> Result<(), String> {
    let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
    // Log axis: only positive finite amplitudes are drawn.
    let points = |f: &[f64], a: &[f64]| -> Vec<(f64, f64)> {
        f.iter().zip(a).map(|(&x, &y)| (x, y)).filter(|(x, y)| x.is_finite() && y.is_finite() && *y > 0.0).collect()
    };
    let sim = points(&simulated.0, &simulated.1);
    let meas: Vec<(&str, Vec<(f64, f64)>)> =
        measured.iter().map(|m| (m.label.as_str(), points(&m.frequency_hz, &m.amplitude))).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in sim.iter().chain(meas.iter().flat_map(|m| m.1.iter())) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !x0.is_finite() {
        return Err("no positive amplitude to plot".into());
    }
    if x1 <= x0 {
        (x0, x1) = (x0 - 1.0, x1 + 1.0);
    }
    // Finite axis ends whatever the data (see `AXIS_LIMIT`).
    let (x, y) = (linear_axis(x0, x1), log_axis(y0, y1));
    let (ly0, ly1) = (y.start, y.end);
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(85)
        .build_cartesian_2d(x, y.log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("Frequency (Hz)")
        .y_desc(format!("|FRF| ({})", unit_text(unit)))
        .y_label_formatter(&|y| log_tick(*y, ly0, ly1))
        .label_style((FONT, 15))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(LineSeries::new(sim.iter().copied(), BLACK.stroke_width(2)))
        .map_err(e)?
        .label("simulated")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    for (i, (label, pts)) in meas.iter().enumerate() {
        let color = Palette99::pick(i + 1).to_rgba();
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(e)?
            .label(format!("measured {label}"))
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled()));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, BLACK.stroke_width(1)))).map_err(e)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 15))
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// One quantity against the modal amplitude on a log axis (a backbone spans decades).
fn draw_against_amplitude<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    points: &[(f64, f64)],
) -> Result<(), String> {
    let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
    root.fill(&WHITE).map_err(e)?;
    let kept: Vec<(f64, f64)> =
        points.iter().copied().filter(|(a, y)| a.is_finite() && *a > 0.0 && y.is_finite()).collect();
    let (a0, a1) = min_max(kept.iter().map(|p| p.0));
    let (y0, y1) = min_max(kept.iter().map(|p| p.1));
    let x = if kept.is_empty() { 1e-6..1.0 } else { a0.max(f64::MIN_POSITIVE) * 1.05..a1 * 1.05 };
    let x = log_axis(x.start / 1.05, x.end / 1.05);
    let (lx0, lx1) = (x.start, x.end);
    let (y0, y1) = if kept.is_empty() { (0.0, 1.0) } else { (y0, y1) };
    let pad = 0.05 * (y1 - y0).max(1e-3 * y0.abs().max(y1.abs())).max(f64::MIN_POSITIVE);
    let y = linear_axis(y0 - pad, y1 + pad);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(85)
        .build_cartesian_2d(x.log_scale(), y.clone())
        .map_err(e)?;
    let span = y.end - y.start;
    chart
        .configure_mesh()
        .x_desc("modal amplitude (m·√kg)")
        .y_desc(y_label)
        .x_label_formatter(&|a| log_tick(*a, lx0, lx1))
        .y_label_formatter(&|v| tick(*v, span))
        .label_style((FONT, 15))
        .draw()
        .map_err(e)?;
    let color = Palette99::pick(0).to_rgba();
    chart.draw_series(LineSeries::new(kept.iter().copied(), color.stroke_width(2))).map_err(e)?;
    chart.draw_series(kept.iter().map(|&p| Circle::new(p, 2, color.filled()))).map_err(e)?;
    root.present().map_err(e)
}

fn render_against_amplitude(path: &Path, title: &str, y_label: &str, points: &[(f64, f64)]) -> Result<(), OutputError> {
    let plot_error = |m: String| OutputError::Plot(format!("{}: {m}", path.display()));
    match path.extension().and_then(|x| x.to_str()) {
        Some("svg") => draw_against_amplitude(SVGBackend::new(path, SIZE).into_drawing_area(), title, y_label, points)
            .map_err(plot_error),
        Some("png") => {
            draw_against_amplitude(BitMapBackend::new(path, SIZE).into_drawing_area(), title, y_label, points)
                .map_err(plot_error)
        }
        _ => Err(plot_error("the plot file name must end in .png or .svg".into())),
    }
}

/// The displacement FRF of `output` per level by the harmonic balance (solid) beside the one
/// synthesised from the nonlinear mode alone (dashed, [`crate::backbone::single_mode_frfs`];
/// `o` is the output's index among the backbone's), so that a reader sees where a single mode
/// holds.
pub fn plot_single_mode(
    path: &Path,
    levels: &[LevelResult],
    output: &str,
    synthesised: &[crate::backbone::SingleModeFrf],
    o: usize,
) -> Result<(), OutputError> {
    let mut curves = Vec::new();
    for l in levels {
        if let Some(p0) = l.points.first() {
            let i = output_index(p0, output)?;
            let points = l.points.iter().map(|p| (p.frequency_hz, p.outputs[i].disp_frf)).collect();
            curves.push(Curve { label: format!("{} N", l.level_n), points, dashed: Vec::new() });
        }
    }
    // The synthesised curves reach far from the resonance; drawn over the harmonic balance's
    // band only, where the two are compared.
    let (lo, hi) = min_max(levels.iter().flat_map(|l| l.points.iter().map(|p| p.frequency_hz)));
    for frf in synthesised {
        let level = frf.level_n;
        let points: Vec<(f64, f64)> =
            frf.points.iter().filter(|(f, _)| (lo..=hi).contains(f)).map(|(f, v)| (*f, v[o])).collect();
        let dashed = vec![true; points.len()];
        curves.push(Curve { label: format!("{level} N, one mode"), points, dashed });
    }
    Chart {
        title: format!("FRF of {output}: harmonic balance (solid) and single nonlinear mode (dashed)"),
        x_label: "Frequency (Hz)".into(),
        y_label: "Displacement / force (m/N)".into(),
        log_y: true,
        curves,
        markers: Vec::new(),
    }
    .render(path)
}

/// The backbone of a nonlinear mode: `backbone_frequency` (Hz) and `backbone_damping`
/// (damping ratio ζ = ξ/2Ω) against the modal amplitude (log axis), in `dir`.
pub fn plot_backbone(
    dir: &Path,
    backbone: &stickslip_core::hbm::Backbone,
    format: PlotFormat,
) -> Result<Vec<PathBuf>, OutputError> {
    let mode = backbone.mode + 1;
    let ext = format.extension();
    let frequency: Vec<(f64, f64)> = backbone.points.iter().map(|p| (p.amplitude, p.frequency_hz())).collect();
    let damping: Vec<(f64, f64)> = backbone.points.iter().map(|p| (p.amplitude, p.damping_ratio())).collect();
    let f_path = dir.join(format!("backbone_frequency.{ext}"));
    render_against_amplitude(&f_path, &format!("Nonlinear mode {mode}: frequency"), "frequency (Hz)", &frequency)?;
    let d_path = dir.join(format!("backbone_damping.{ext}"));
    render_against_amplitude(&d_path, &format!("Nonlinear mode {mode}: damping ratio"), "damping ratio ζ", &damping)?;
    Ok(vec![f_path, d_path])
}

#[cfg(test)]
mod tests {
    /// The tick labels in exponent form of an SVG plot.
    fn exponent_labels(svg: &str) -> Vec<String> {
        svg.split('>')
            .filter_map(|t| t.split('<').next())
            .map(str::trim)
            .filter(|t| t.contains('e') && t.parse::<f64>().is_ok())
            .map(String::from)
            .collect()
    }

    #[test]
    fn the_comparison_and_backbone_log_axes_label_their_decades() {
        // Five decades: the decades alone are labelled (as every log axis of the FRF plots);
        // about one: the ticks at 1, 2 and 5 too, so that values can be read, not all nine.
        let dir = std::env::temp_dir().join(format!("stickslip-plot-decades-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (decades, name) in [(5.0, "five"), (0.9, "one")] {
            let f: Vec<f64> = (0..200).map(|i| 10.0 + i as f64).collect();
            let a: Vec<f64> = f.iter().map(|x| 1e-6 * 10f64.powf(decades * (x - 10.0) / 199.0)).collect();
            let measured = [super::MeasuredCurve { label: "m".into(), frequency_hz: f.clone(), amplitude: a.clone() }];
            let compared = dir.join(format!("compare_{name}.svg"));
            super::plot_comparison(&compared, "tip at 1 N", "m_per_N", &(f, a), &measured).unwrap();
            let backbone = dir.join(format!("backbone_{name}.svg"));
            let points: Vec<(f64, f64)> =
                (0..50).map(|i| (1e-6 * 10f64.powf(decades * i as f64 / 49.0), 100.0 - i as f64)).collect();
            super::render_against_amplitude(&backbone, "mode 1", "frequency (Hz)", &points).unwrap();
            for path in [compared, backbone] {
                let labels = exponent_labels(&std::fs::read_to_string(&path).unwrap());
                let decade = |l: &String| l.starts_with("1e");
                if decades > 3.0 {
                    assert!(labels.len() >= 4 && labels.iter().all(decade), "{}: {labels:?}", path.display());
                } else {
                    // Not every tick plotters places (1e-6, 2e-6, 3e-6, ..., 9e-6: crowded, as
                    // the formatter of before labelled them).
                    let readable = |l: &String| ["1e", "2e", "5e"].iter().any(|m| l.starts_with(m));
                    assert!(
                        labels.len() >= 4 && labels.iter().all(readable) && !labels.iter().all(decade),
                        "{}: {labels:?}",
                        path.display()
                    );
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn log_axes_label_the_decades_or_enough_ticks_to_read_values_by() {
        use super::log_tick;
        // Three decades: the decades only.
        let (y0, y1) = (2e-7, 5e-4);
        assert_eq!(log_tick(1e-6, y0, y1), "1e-6");
        assert_eq!(log_tick(2e-6, y0, y1), "");
        // Less than a decade, across 1e0 (a resonance's top): 1, 2, 3 and 5 of the decade.
        let (y0, y1) = (0.73, 7.05);
        let labels: Vec<String> =
            [0.8, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0].iter().map(|y| log_tick(*y, y0, y1)).collect();
        assert_eq!(labels, ["", "1e0", "2e0", "3e0", "", "5e0", "", ""]);
        // Inside one decade, no decade tick at all: still labels.
        assert_eq!(log_tick(3e-4, 2.1e-4, 9e-4), "3e-4");
        // Two decade ticks (1e0 and 1e1): 1, 2 and 5 of each decade.
        let (y0, y1) = (0.7, 33.0);
        let labels: Vec<String> = [0.8, 1.0, 2.0, 3.0, 5.0, 20.0, 30.0].iter().map(|y| log_tick(*y, y0, y1)).collect();
        assert_eq!(labels, ["", "1e0", "2e0", "", "5e0", "2e1", ""]);
        // Three (1e-3 to 1e-1 inside): the decades only.
        assert_eq!(log_tick(2e-2, 8e-4, 0.2), "");
        assert_eq!(log_tick(1e-2, 8e-4, 0.2), "1e-2");
    }

    /// The even harmonics of a half-wave symmetric response are exact zeros: labelled so, the
    /// others as they are (one of them zero at one point only).
    #[test]
    fn harmonics_zero_at_every_point_are_labelled_zero() {
        use crate::output::{LevelResult, OutputRecord, PointRecord};
        let point = |f: f64, a3: f64| PointRecord {
            frequency_hz: f,
            outputs: vec![OutputRecord {
                name: "mass".into(),
                harmonics: vec![(0.0, 0.0), (1e-3, 0.1), (0.0, 0.0), (a3, 0.2)],
                ..OutputRecord::default()
            }],
            ..PointRecord::default()
        };
        let level =
            LevelResult { level_n: 10.0, points: vec![point(100.0, 1e-5), point(101.0, 0.0)], ..Default::default() };
        let labels: Vec<String> = super::harmonic_curves(&level, 0).into_iter().map(|c| c.label).collect();
        assert_eq!(labels, ["harmonic 1", "harmonic 2 (zero)", "harmonic 3"]);
    }

    /// The centres of an SVG plot's circles (pixels).
    fn circle_centres(svg: &str) -> Vec<(i64, i64)> {
        let attribute = |element: &str, name: &str| -> i64 {
            let at = element.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
            element[at..].split('"').next().unwrap().parse().unwrap()
        };
        svg.split("<circle").skip(1).map(|c| (attribute(c, "cx"), attribute(c, "cy"))).collect()
    }

    /// The curves' polylines (2 px wide) of an SVG plot: their colour and vertices (pixels), in
    /// the order drawn.
    fn curve_polylines(svg: &str) -> Vec<(String, Vec<(i64, i64)>)> {
        let attribute = |element: &str, name: &str| -> String {
            let at = element.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
            element[at..].split('"').next().unwrap().to_string()
        };
        svg.split("<polyline")
            .skip(1)
            .filter(|l| attribute(l, "stroke-width") == "2")
            .map(|l| {
                let vertices = attribute(l, "points")
                    .split_whitespace()
                    .map(|p| {
                        let (x, y) = p.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect();
                (attribute(l, "stroke"), vertices)
            })
            .collect()
    }

    /// The colour of the curve that has each circle's centre as a vertex (a marker on its
    /// curve, at one of its points); panics when a circle is on no curve or on two.
    fn curves_marked(svg: &str) -> Vec<String> {
        let lines = curve_polylines(svg);
        circle_centres(svg)
            .into_iter()
            .map(|c| {
                let mut on = lines.iter().filter(|l| l.1.contains(&c)).map(|l| l.0.clone()).collect::<Vec<_>>();
                on.dedup();
                assert_eq!(on.len(), 1, "marker at {c:?} on curves {on:?}");
                on.remove(0)
            })
            .collect()
    }

    /// How many text elements of an SVG plot read `label`.
    fn labels(svg: &str, label: &str) -> usize {
        svg.split('>').filter_map(|t| t.split('<').next()).filter(|t| t.trim() == label).count()
    }

    /// A level over 100..110 Hz whose harmonics come from Fourier coefficients as a sweep's do:
    /// harmonic 1 of amplitude `scale` (1 + i) and phase −`rate` i rad (−0.65 i wraps past −π at
    /// 105 Hz); harmonic 2 exactly zero (a half-wave symmetric response); harmonic 3 smaller.
    /// With `fold`, a fold at 105 Hz recorded as the sweep records it, and the points after
    /// 106 Hz unstable.
    fn folded_level(level_n: f64, scale: f64, rate: f64, fold: bool) -> crate::output::LevelResult {
        use crate::output::{
            harmonics_from_coefficients, BifurcationRecord, LevelResult, OutputRecord, PointRecord, PointStability,
        };
        let coefficients = |i: usize| {
            let (a1, p1) = (scale * (1.0 + i as f64), -rate * i as f64);
            let (a3, p3) = (1e-2 * a1, 0.4 * i as f64);
            vec![0.0, a1 * p1.cos(), -a1 * p1.sin(), 0.0, 0.0, a3 * p3.cos(), -a3 * p3.sin()]
        };
        let points = (0..=10)
            .map(|i| {
                let harmonics = harmonics_from_coefficients(&coefficients(i));
                PointRecord {
                    frequency_hz: 100.0 + i as f64,
                    outputs: vec![OutputRecord {
                        name: "mass".into(),
                        disp_frf: harmonics[1].0 / level_n,
                        harmonics,
                        ..OutputRecord::default()
                    }],
                    stability: fold.then_some(PointStability {
                        stable: i <= 6,
                        exponent_re: if i <= 6 { -1.0 } else { 1.0 },
                        exponent_im: 0.0,
                    }),
                    ..PointRecord::default()
                }
            })
            .collect();
        let bifurcations = if fold {
            let harmonics = harmonics_from_coefficients(&coefficients(5));
            vec![BifurcationRecord {
                level_n,
                kind: "fold".into(),
                frequency_hz: 105.0,
                harmonics: vec![("mass".into(), harmonics)],
                exponent_im: 0.0,
                located: true,
            }]
        } else {
            Vec::new()
        };
        LevelResult { level_n, points, bifurcations, ..Default::default() }
    }

    /// The plots of one point (hysteresis, slider velocity) say in their titles when the point
    /// is unstable, as the FRF plots dash it; a stable point's titles do not.
    #[test]
    fn plots_of_an_unstable_point_say_so_in_their_titles() {
        use crate::output::{ElementRecord, PointRecord, PointStability};
        let dir = std::env::temp_dir().join(format!("stickslip-plot-unstable-point-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let point = |stable: bool| PointRecord {
            frequency_hz: 230.0,
            elements: vec![ElementRecord {
                name: "blade1".into(),
                loop_u: vec![0.0, 1e-5, 0.0, -1e-5],
                loop_force: vec![0.0, 290.0, 0.0, -290.0],
                slider_velocity: vec![0.0, 1e-3, 0.0, -1e-3],
                ..ElementRecord::default()
            }],
            stability: Some(PointStability { stable, exponent_re: if stable { -1.0 } else { 2.0 }, exponent_im: 0.0 }),
            ..PointRecord::default()
        };
        for stable in [true, false] {
            let (h, v) = (dir.join(format!("h{stable}.svg")), dir.join(format!("v{stable}.svg")));
            super::plot_hysteresis(&h, 2910.0, &point(stable), "blade1").unwrap();
            super::plot_slider_velocity(&v, 2910.0, &point(stable), "blade1").unwrap();
            for path in [h, v] {
                let svg = std::fs::read_to_string(&path).unwrap();
                assert_eq!(svg.contains("(unstable)"), !stable, "{}", path.display());
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The fold of a level is marked on its phase curve (at the phase the curve has there, past
    /// the wrap at −180°) and on harmonics 1 and 3 of its harmonics plot (not on harmonic 2,
    /// zero); a level without bifurcations carries no marker. Titles say what dashes mean.
    #[test]
    fn phase_and_harmonics_plots_mark_the_bifurcations_on_their_curves() {
        let dir = std::env::temp_dir().join(format!("stickslip-plot-marked-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (folded, plain) = (folded_level(10.0, 1e-4, 0.65, true), folded_level(20.0, 3e-4, 0.3, false));
        let labels = |svg: &str| labels(svg, "LP");
        let read = |path: &std::path::Path| std::fs::read_to_string(path).unwrap();

        let both = dir.join("phase_both.svg");
        super::plot_frf_phase(&both, &[folded.clone(), plain.clone()], "mass").unwrap();
        let svg = read(&both);
        assert_eq!(labels(&svg), 1, "one fold, one label");
        // On the folded level's curve (the first drawn), at its point of 105 Hz: past the wrap,
        // near +180°, as the curve has it.
        assert_eq!(curves_marked(&svg), [curve_polylines(&svg)[0].0.clone()]);
        assert!(svg.contains("one curve per level; dashed: unstable"), "the title says what dashes mean");

        let harmonics = dir.join("harmonics_folded.svg");
        super::plot_harmonics(&harmonics, &folded, "mass").unwrap();
        let svg = read(&harmonics);
        assert_eq!(labels(&svg), 2, "marked on harmonics 1 and 3");
        let marked = curves_marked(&svg);
        assert_eq!(marked.len(), 2);
        assert_ne!(marked[0], marked[1], "on two curves");
        assert!(svg.contains("Harmonics of mass at 10 N (dashed: unstable)"));

        let (phase, harmonics) = (dir.join("phase_plain.svg"), dir.join("harmonics_plain.svg"));
        super::plot_frf_phase(&phase, std::slice::from_ref(&plain), "mass").unwrap();
        super::plot_harmonics(&harmonics, &plain, "mass").unwrap();
        for path in [phase, harmonics] {
            let (svg, name) = (read(&path), path.display());
            assert_eq!((labels(&svg), circle_centres(&svg).len()), (0, 0), "{name}: no bifurcation, no marker");
            assert!(!svg.contains("dashed"), "{name}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn ticks_at_round_off_of_zero_read_zero() {
        // The tick at zero of a velocity axis [-0.14, 0.12] came out as -1.39e-17.
        assert_eq!(super::tick(-1.39e-17, 0.26), "0");
        assert_eq!(super::tick(0.05, 0.26), "0.05");
        // A genuinely small tick on a small axis keeps its value.
        assert_eq!(super::tick(2.0e-9, 1.0e-8), "2.00e-9");
    }
}
