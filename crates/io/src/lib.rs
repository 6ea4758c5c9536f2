//! stickslip-io: files in and out (study files, matrix formats, CSV/NPZ/UFF, plots, the HTML report).
pub mod analysis;
pub mod backbone;
pub mod matrix;
pub mod output;
pub mod params;
#[cfg(feature = "plot")]
pub mod plot;
pub mod records;
pub mod report;
pub mod study;
pub mod uff;
