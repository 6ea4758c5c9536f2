//! Which values the samples take: `--vary KEY=SPEC` specifications, a full grid or a seeded
//! Latin hypercube.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};

use super::ParamError;

/// The values of one varied key.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// `LO:HI`: a range, sampled by a Latin hypercube.
    Range { low: f64, high: f64 },
    /// `LO:HI:N`: N evenly spaced values, ends included (a grid axis).
    Spaced { low: f64, high: f64, count: usize },
    /// `a,b,c`: the values given (a grid axis).
    List(Vec<f64>),
}

/// `KEY=SPEC`, as given on the command line or built from Python.
#[derive(Clone, Debug, PartialEq)]
pub struct Vary {
    pub key: String,
    pub values: Values,
}

impl Vary {
    /// Parse `KEY=LO:HI`, `KEY=LO:HI:N` or `KEY=a,b,c`.
    pub fn parse(text: &str) -> Result<Vary, ParamError> {
        let spec_error = |message: String| ParamError::Spec { spec: text.to_string(), message };
        let Some((key, spec)) = text.split_once('=') else {
            return Err(spec_error("expected KEY=LO:HI (a range), KEY=LO:HI:N (N grid values) or KEY=a,b,c".into()));
        };
        let (key, spec) = (key.trim(), spec.trim());
        let number = |s: &str| -> Result<f64, ParamError> {
            let x: f64 = s.trim().parse().map_err(|_| spec_error(format!("`{}` is not a number", s.trim())))?;
            if !x.is_finite() {
                return Err(spec_error(format!("`{}` is not a finite number", s.trim())));
            }
            Ok(x)
        };
        let values =
            if spec.contains(':') {
                let parts: Vec<&str> = spec.split(':').collect();
                let (low, high) = (number(parts[0])?, number(parts[1])?);
                if low >= high {
                    return Err(spec_error(format!("the range {low}:{high} is empty: LO must be below HI")));
                }
                match parts.len() {
                    2 => Values::Range { low, high },
                    3 => {
                        let count =
                            parts[2].trim().parse::<usize>().ok().filter(|n| *n >= 2).ok_or_else(|| {
                                spec_error(format!("N = `{}` must be an integer >= 2", parts[2].trim()))
                            })?;
                        Values::Spaced { low, high, count }
                    }
                    _ => return Err(spec_error("expected LO:HI or LO:HI:N".into())),
                }
            } else {
                Values::List(spec.split(',').map(number).collect::<Result<_, _>>()?)
            };
        Ok(Vary { key: key.to_string(), values })
    }

    /// The values a design may give this key, to check them against the study before running:
    /// the ends of a range, every value of a grid axis.
    pub fn extremes(&self) -> Vec<f64> {
        match &self.values {
            Values::Range { low, high } | Values::Spaced { low, high, .. } => vec![*low, *high],
            Values::List(v) => v.clone(),
        }
    }
}

/// The samples of a study: one row of values per sample, in the order of the varied keys.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    pub samples: Vec<Vec<f64>>,
    /// How the samples were drawn, in words (for tables and errors).
    pub method: String,
}

/// The samples for `varies`: a Latin hypercube of `samples` points seeded by `seed` when the
/// keys are ranges, the full grid (first key slowest) when they are value lists.
pub fn design(varies: &[Vary], samples: Option<usize>, seed: u64) -> Result<Design, ParamError> {
    if varies.is_empty() {
        return Err(ParamError::Design("vary at least one key (KEY=LO:HI, KEY=LO:HI:N or KEY=a,b,c)".into()));
    }
    let ranges = varies.iter().filter(|v| matches!(v.values, Values::Range { .. })).count();
    if ranges > 0 && ranges < varies.len() {
        return Err(ParamError::Design(
            "a Latin hypercube (KEY=LO:HI) cannot be mixed with grid axes (KEY=LO:HI:N or KEY=a,b,c): give all keys one way".into(),
        ));
    }
    if ranges > 0 {
        let n = samples
            .filter(|n| *n >= 1)
            .ok_or_else(|| ParamError::Design("a Latin hypercube (KEY=LO:HI) needs a number of samples >= 1".into()))?;
        let bounds: Vec<(f64, f64)> = varies
            .iter()
            .map(|v| match v.values {
                Values::Range { low, high } => (low, high),
                _ => unreachable!("all keys are ranges"),
            })
            .collect();
        return Ok(Design {
            samples: latin_hypercube(&bounds, n, seed),
            method: format!("Latin hypercube, seed {seed}"),
        });
    }
    if let Some(n) = samples {
        return Err(ParamError::Design(format!(
            "{n} samples asked, but a grid (KEY=LO:HI:N or KEY=a,b,c) has its own number of samples; give ranges KEY=LO:HI for a Latin hypercube"
        )));
    }
    let axes: Vec<Vec<f64>> = varies
        .iter()
        .map(|v| match &v.values {
            Values::Spaced { low, high, count } => {
                (0..*count).map(|i| low + (high - low) * i as f64 / (*count - 1) as f64).collect()
            }
            Values::List(values) => values.clone(),
            Values::Range { .. } => unreachable!("no ranges in a grid"),
        })
        .collect();
    let total: usize = axes.iter().map(Vec::len).product();
    let mut samples = Vec::with_capacity(total);
    for i in 0..total {
        // Mixed radix, the last key fastest.
        let mut rest = i;
        let mut row = vec![0.0; axes.len()];
        for (d, axis) in axes.iter().enumerate().rev() {
            row[d] = axis[rest % axis.len()];
            rest /= axis.len();
        }
        samples.push(row);
    }
    Ok(Design { samples, method: "grid".into() })
}

/// Latin hypercube: each range cut in `n` equal strata, each stratum used by exactly one
/// sample, a uniform point inside it; strata paired across keys by independent permutations.
/// The generator is seeded, so a seed gives the same samples on every machine.
fn latin_hypercube(bounds: &[(f64, f64)], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut samples = vec![vec![0.0; bounds.len()]; n];
    for (d, &(low, high)) in bounds.iter().enumerate() {
        let mut strata: Vec<usize> = (0..n).collect();
        strata.shuffle(&mut rng);
        for (i, s) in strata.into_iter().enumerate() {
            let u: f64 = rng.random();
            samples[i][d] = low + (high - low) * (s as f64 + u) / n as f64;
        }
    }
    samples
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin_hypercube_puts_one_sample_in_each_stratum_and_repeats_with_its_seed() {
        let v = [Vary::parse("a=0:1").unwrap(), Vary::parse("b=10:20").unwrap()];
        let d = design(&v, Some(40), 7).unwrap();
        assert_eq!(d.samples.len(), 40);
        for (k, (low, high)) in [(0, (0.0, 1.0)), (1, (10.0, 20.0))] {
            let mut strata: Vec<usize> =
                d.samples.iter().map(|s| ((s[k] - low) / (high - low) * 40.0).floor() as usize).collect();
            strata.sort();
            // Exactly one sample per stratum 0..40 on each key.
            assert_eq!(strata, (0..40).collect::<Vec<_>>());
        }
        assert_eq!(design(&v, Some(40), 7).unwrap(), d);
        assert_ne!(design(&v, Some(40), 8).unwrap().samples, d.samples);
    }

    #[test]
    fn grid_is_the_product_with_the_last_key_fastest() {
        let v = [Vary::parse("a=1,2").unwrap(), Vary::parse("b=0:1:3").unwrap()];
        let d = design(&v, None, 0).unwrap();
        let expected = [[1.0, 0.0], [1.0, 0.5], [1.0, 1.0], [2.0, 0.0], [2.0, 0.5], [2.0, 1.0]];
        assert_eq!(d.samples, expected.iter().map(|r| r.to_vec()).collect::<Vec<_>>());
    }

    #[test]
    fn bad_specifications_say_what_is_expected() {
        let e = Vary::parse("a=3:1").unwrap_err().to_string();
        assert!(e.contains("LO must be below HI"), "{e}");
        let e = Vary::parse("a=1:x").unwrap_err().to_string();
        assert!(e.contains("`x` is not a number"), "{e}");
        let e = design(&[Vary::parse("a=0:1").unwrap(), Vary::parse("b=1,2").unwrap()], Some(3), 0).unwrap_err();
        assert!(e.to_string().contains("cannot be mixed"), "{e}");
    }
}
