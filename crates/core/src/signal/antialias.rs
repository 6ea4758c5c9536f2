//! The anti-aliasing filter of a data acquisition system.
//!
//! A test system low-pass filters every channel before sampling it, so that nothing above the
//! Nyquist frequency folds into the band of interest. A simulation sampled every m-th time
//! step needs the same: stick-slip transitions of stiff joints excite modes far above the
//! band (kHz to MHz for 1e10 N/m connectors), and their accelerations, sampled sparsely, fold
//! onto the harmonics as noise of tens of percent. The filter is an 8th-order Butterworth
//! (four second-order sections from the `biquad` crate, bilinear transform prewarped at the
//! cutoff), run at the integration rate. It delays and attenuates every channel identically,
//! so ratios of channels at one frequency (FRFs against the drive signal, the force
//! identification of Eq. 1) are unaffected; harmonics of one channel alone carry its gain,
//! which is flat to 1e-5 below half the cutoff.

use biquad::{Biquad, Coefficients, DirectForm2Transposed, ToHertz, Type};

use super::SignalError;

/// Order of the Butterworth filter: with the cutoff at 0.4 of the output sample rate, content
/// that would fold below 0.2 of it is attenuated by 46 dB or more.
const ORDER: usize = 8;

/// One channel's filter: a cascade of second-order sections.
#[derive(Clone, Debug)]
pub struct AntiAliasFilter {
    sections: Vec<DirectForm2Transposed<f64>>,
}

impl AntiAliasFilter {
    /// Butterworth low-pass of cutoff `cutoff_hz` for samples at `sample_rate_hz`.
    pub fn new(sample_rate_hz: f64, cutoff_hz: f64) -> Result<Self, SignalError> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(SignalError::BadSampleRate(sample_rate_hz));
        }
        if !(cutoff_hz > 0.0 && cutoff_hz < 0.5 * sample_rate_hz) {
            return Err(SignalError::Invalid(format!(
                "the anti-aliasing cutoff must be between 0 and half the sample rate ({} Hz), got {cutoff_hz} Hz",
                0.5 * sample_rate_hz
            )));
        }
        // The poles of a Butterworth filter of order 2K pair into sections of quality factor
        // Q_k = 1 / (2 cos((2k+1) π / 4K)).
        let pairs = ORDER / 2;
        let sections = (0..pairs)
            .map(|k| {
                let q = 1.0 / (2.0 * ((2 * k + 1) as f64 * std::f64::consts::PI / (4 * pairs) as f64).cos());
                Coefficients::<f64>::from_params(Type::LowPass, sample_rate_hz.hz(), cutoff_hz.hz(), q)
                    .map(DirectForm2Transposed::<f64>::new)
                    .map_err(|e| SignalError::Invalid(format!("anti-aliasing filter: {e:?}")))
            })
            .collect::<Result<_, _>>()?;
        Ok(AntiAliasFilter { sections })
    }

    /// Filter one sample.
    pub fn run(&mut self, x: f64) -> f64 {
        self.sections.iter_mut().fold(x, |y, s| s.run(y))
    }
}
