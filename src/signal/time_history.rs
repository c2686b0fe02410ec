//! Time histories: a scalar signal sampled at increasing times, interpolated linearly between
//! its samples (zero outside them), with its exact first and second integrals (what a base
//! motion given as an acceleration or a velocity needs), read from numbers or CSV files.

use crate::error::{Error, Result};
use crate::math::Real;

/// A scalar signal sampled at strictly increasing times, linear between samples and zero
/// outside `[first time, last time]`.
///
/// # Example
/// ```
/// use voussoir::loading::TimeHistory;
///
/// let a = TimeHistory::new(vec![0.0, 1.0, 2.0], vec![0.0, 2.0, 0.0])?;
/// assert_eq!(a.value_at(0.5), 1.0);
/// assert_eq!(a.value_at(3.0), 0.0);
/// // A CSV accelerogram in g, scaled to m/s²: time in column 0, acceleration in column 1.
/// let record = "t [s],a [g]\n0.0,0.0\n0.01,0.1\n0.02,-0.05\n";
/// let a = TimeHistory::from_csv(record, 0, 1, 9.81)?;
/// assert!((a.value_at(0.01) - 0.981).abs() < 1e-12);
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "TimeHistoryData"))]
#[cfg_attr(feature = "serde", serde(into = "TimeHistoryData"))]
pub struct TimeHistory {
    times: Vec<Real>,
    values: Vec<Real>,
    /// `(∫h, ∫∫h)` from the first sample to each sample.
    integrals: Vec<(Real, Real)>,
}

/// The serialised form, validated into a [`TimeHistory`] on load.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeHistoryData {
    times: Vec<Real>,
    values: Vec<Real>,
}

#[cfg(feature = "serde")]
impl TryFrom<TimeHistoryData> for TimeHistory {
    type Error = Error;
    fn try_from(d: TimeHistoryData) -> Result<Self> {
        Self::new(d.times, d.values)
    }
}

#[cfg(feature = "serde")]
impl From<TimeHistory> for TimeHistoryData {
    fn from(h: TimeHistory) -> Self {
        Self {
            times: h.times,
            values: h.values,
        }
    }
}

impl TimeHistory {
    /// A history from its samples.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for fewer than two samples, lengths that differ, times
    /// that do not strictly increase; [`Error::NonFinite`] for a non-finite time or value.
    pub fn new(times: Vec<Real>, values: Vec<Real>) -> Result<Self> {
        if times.len() != values.len() {
            return Err(Error::InvalidParameter {
                name: "time history".into(),
                value: values.len() as Real,
                expected: "as many values as times",
            });
        }
        if times.len() < 2 {
            return Err(Error::InvalidParameter {
                name: "time history".into(),
                value: times.len() as Real,
                expected: "at least two samples",
            });
        }
        for (i, (&t, &v)) in times.iter().zip(&values).enumerate() {
            if !t.is_finite() || !v.is_finite() {
                return Err(Error::NonFinite {
                    what: format!("time history sample {i} (t = {t}, value = {v})"),
                });
            }
            if i > 0 && t <= times[i - 1] {
                return Err(Error::InvalidParameter {
                    name: format!("time history: time of sample {i}"),
                    value: t,
                    expected: "times that strictly increase",
                });
            }
        }
        let mut integrals = Vec::with_capacity(times.len());
        let (mut v, mut u) = (0.0, 0.0);
        integrals.push((v, u));
        for k in 0..times.len() - 1 {
            (v, u) = segment_integral(
                times[k + 1] - times[k],
                values[k],
                values[k + 1],
                times[k + 1] - times[k],
                v,
                u,
            );
            integrals.push((v, u));
            let slope = (values[k + 1] - values[k]) / (times[k + 1] - times[k]);
            if !(slope.is_finite() && v.is_finite() && u.is_finite()) {
                return Err(Error::InvalidParameter {
                    name: format!(
                        "time history: samples {k} and {} (times {} and {})",
                        k + 1,
                        times[k],
                        times[k + 1]
                    ),
                    value: slope,
                    expected: "samples whose slope and integrals are finite (times this close, or values this \
                               large, overflow f64)",
                });
            }
        }
        Ok(Self {
            times,
            values,
            integrals,
        })
    }

    /// `amplitude · sin(2π f t)` from 0 to `duration`, sampled `samples_per_period` times per
    /// period (a shaking-table test).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-positive frequency, duration or sample count, or
    /// one that would take more than ten million samples; [`Error::NonFinite`] for a non-finite
    /// amplitude.
    pub fn sine(amplitude: Real, frequency: Real, duration: Real, samples_per_period: u32) -> Result<Self> {
        crate::error::positive("sine frequency", frequency)?;
        crate::error::positive("sine duration", duration)?;
        crate::error::positive("sine samples per period", Real::from(samples_per_period))?;
        if !amplitude.is_finite() {
            return Err(Error::NonFinite {
                what: "sine amplitude".into(),
            });
        }
        let samples = (duration * frequency * Real::from(samples_per_period)).ceil();
        if samples > 1e7 {
            return Err(Error::InvalidParameter {
                name: "sine samples".into(),
                value: samples,
                expected: "at most ten million samples",
            });
        }
        let n = samples as usize;
        let h = duration / n as Real;
        let times: Vec<Real> = (0..=n).map(|i| i as Real * h).collect();
        let values = times
            .iter()
            .map(|t| amplitude * (2.0 * std::f64::consts::PI * frequency * t).sin())
            .collect();
        Self::new(times, values)
    }

    /// A history from two columns of CSV text (comma, semicolon, tab or blank separated; lines
    /// that do not parse as numbers in both columns, such as a header, are skipped, as are
    /// blank lines and lines starting with `#`), its values multiplied by `scale` (9.81 for a
    /// record in g). Numbers may be quoted (`"0.5"`); lines may end in LF, CR LF or CR alone.
    /// The decimal point is `.`: a line with both `;` (or a tab) and `,` is refused as written
    /// with decimal commas (`1,5;0,3`), which would otherwise read as other numbers.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the line of a row that has the columns but a value
    /// that is not a number after the first numeric row, a line with decimal commas, text
    /// holding NUL characters (UTF-16), fewer than two numeric rows (saying how many lines were
    /// read and skipped, and the first one skipped), and as [`TimeHistory::new`].
    pub fn from_csv(text: &str, time_column: usize, value_column: usize, scale: Real) -> Result<Self> {
        if !scale.is_finite() {
            return Err(Error::NonFinite {
                what: "time history scale".into(),
            });
        }
        if text.contains('\0') {
            return Err(Error::InvalidParameter {
                name: "time history CSV".into(),
                value: text.find('\0').unwrap_or(0) as Real,
                expected: "text without NUL characters (a UTF-16 file? save it as UTF-8); \
                           the value is the position of the first NUL",
            });
        }
        // Lines ended by CR alone (old Mac files) are split at CR.
        let text: std::borrow::Cow<'_, str> = if text.contains('\n') {
            text.into()
        } else {
            text.replace('\r', "\n").into()
        };
        let (mut times, mut values) = (Vec::new(), Vec::new());
        let (mut read, mut skipped, mut first_skipped) = (0usize, 0usize, None);
        for (line_no, line) in text.lines().enumerate() {
            let line = line.trim().trim_start_matches('\u{feff}');
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            read += 1;
            if line.contains(',') && line.contains([';', '\t']) {
                return Err(Error::InvalidParameter {
                    name: format!("time history CSV line {}: `{line}`", line_no + 1),
                    value: (line_no + 1) as Real,
                    expected: "numbers with a decimal point `.`: this line has both `,` and `;` or a tab, \
                               as numbers written with decimal commas (1,5;0,3) do",
                });
            }
            let fields: Vec<&str> = line.split([',', ';', '\t', ' ']).filter(|f| !f.is_empty()).collect();
            let parse = |c: usize| fields.get(c).map(|f| unquote(f.trim()).parse::<Real>());
            match (parse(time_column), parse(value_column)) {
                (Some(Ok(t)), Some(Ok(v))) => {
                    times.push(t);
                    values.push(v * scale);
                }
                _ if times.is_empty() => {
                    // a header
                    skipped += 1;
                    first_skipped.get_or_insert_with(|| (line_no + 1, line.chars().take(60).collect::<String>()));
                }
                _ => {
                    return Err(Error::InvalidParameter {
                        name: format!("time history CSV line {}: `{line}`", line_no + 1),
                        value: (line_no + 1) as Real,
                        expected: "a number in the time and value columns",
                    })
                }
            }
        }
        if times.len() < 2 {
            let first =
                first_skipped.map_or_else(String::new, |(n, l)| format!("; the first skipped, line {n}: `{l}`"));
            return Err(Error::InvalidParameter {
                name: format!(
                    "time history CSV: {} numeric rows in columns {time_column} and {value_column} of {read} lines \
                     read ({skipped} skipped as not numbers{first})",
                    times.len()
                ),
                value: times.len() as Real,
                expected: "at least two rows with a number in the time and the value column",
            });
        }
        Self::new(times, values)
    }

    /// Reads [`TimeHistory::from_csv`] from a file (UTF-8, with or without a byte-order mark).
    ///
    /// # Errors
    /// [`Error::Io`] naming the file (also for a UTF-16 or other non-UTF-8 file, saying so),
    /// and as [`TimeHistory::from_csv`].
    pub fn from_csv_file(path: &std::path::Path, time_column: usize, value_column: usize, scale: Real) -> Result<Self> {
        let text = crate::file::read_text(path)?;
        Self::from_csv(&text, time_column, value_column, scale)
    }

    /// The sample times (s).
    pub fn times(&self) -> &[Real] {
        &self.times
    }

    /// The sample values.
    pub fn values(&self) -> &[Real] {
        &self.values
    }

    /// The last sample time (s).
    pub fn end(&self) -> Real {
        self.times[self.times.len() - 1]
    }

    /// The segment `[t_k, t_{k+1}]` holding `t` (`None` outside the samples).
    fn segment(&self, t: Real) -> Option<usize> {
        if !(t >= self.times[0] && t <= self.end()) {
            return None;
        }
        // The last k with t_k ≤ t, at most n − 2.
        let k = self.times.partition_point(|&x| x <= t).saturating_sub(1);
        Some(k.min(self.times.len() - 2))
    }

    /// The value at `t`: linear between samples, zero outside them.
    pub fn value_at(&self, t: Real) -> Real {
        let Some(k) = self.segment(t) else { return 0.0 };
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let (v0, v1) = (self.values[k], self.values[k + 1]);
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }
}

/// A CSV field without the double quotes around it.
fn unquote(field: &str) -> &str {
    field
        .strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .map_or(field, str::trim)
}

/// The integrals `(v, u)` after `s` into a segment of length `length` whose values go from
/// `a0` to `a1`, starting from `(v, u)`: with `a(τ) = a0 + (a1 − a0) τ / length`,
/// `v + a0 s + slope s²/2` and `u + v s + a0 s²/2 + slope s³/6`.
fn segment_integral(s: Real, a0: Real, a1: Real, length: Real, v: Real, u: Real) -> (Real, Real) {
    let slope = (a1 - a0) / length;
    (
        v + a0 * s + slope * s * s / 2.0,
        u + v * s + a0 * s * s / 2.0 + slope * s * s * s / 6.0,
    )
}

/// `(∫₀ᵗ h, ∫₀ᵗ∫₀ˢ h)` of a piecewise-linear history that is zero before its first sample
/// and after its last: exact (the first is piecewise quadratic, the second piecewise cubic),
/// from the integrals at the samples (a binary search and a few operations per call).
pub(crate) fn integral(h: &TimeHistory, t: Real) -> (Real, Real) {
    if t <= h.times[0] {
        return (0.0, 0.0);
    }
    match h.segment(t) {
        Some(k) => {
            let (v, u) = h.integrals[k];
            let length = h.times[k + 1] - h.times[k];
            segment_integral(t - h.times[k], h.values[k], h.values[k + 1], length, v, u)
        }
        None => {
            // After the last sample the history is zero: the velocity stays.
            let (v, u) = h.integrals[h.integrals.len() - 1];
            (v, u + v * (t - h.end()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant acceleration integrates to `a t` and `a t²/2` exactly.
    #[test]
    fn integrals_are_exact_for_piecewise_linear_histories() {
        let h = TimeHistory::new(vec![0.0, 0.3, 1.0], vec![2.0, 2.0, 2.0]).unwrap();
        let (v, u) = integral(&h, 0.7);
        assert!((v - 1.4).abs() < 1e-15 && (u - 0.49).abs() < 1e-15, "{v} {u}");
        // A ramp a = t: v = t²/2, u = t³/6.
        let ramp = TimeHistory::new(vec![0.0, 0.5, 2.0], vec![0.0, 0.5, 2.0]).unwrap();
        let (v, u) = integral(&ramp, 1.5);
        assert!((v - 1.125).abs() < 1e-14 && (u - 0.5625).abs() < 1e-14, "{v} {u}");
        // Past the end the velocity holds.
        let (v, u) = integral(&ramp, 3.0);
        assert!(
            (v - 2.0).abs() < 1e-14 && (u - (8.0 / 6.0 + 2.0)).abs() < 1e-14,
            "{v} {u}"
        );
    }

    #[test]
    fn bad_histories_are_errors() {
        assert!(TimeHistory::new(vec![0.0], vec![1.0]).is_err());
        assert!(TimeHistory::new(vec![0.0, 1.0], vec![1.0]).is_err());
        assert!(TimeHistory::new(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
        assert!(TimeHistory::new(vec![0.0, Real::NAN], vec![1.0, 2.0]).is_err());
        assert!(TimeHistory::new(vec![0.0, 1.0], vec![1.0, Real::INFINITY]).is_err());
        assert!(TimeHistory::sine(1.0, 0.0, 1.0, 10).is_err());
        assert!(TimeHistory::sine(1.0, 1e9, 1.0, 10).is_err());
        let e = TimeHistory::from_csv("t,a\n0,1\n0.1,x\n", 0, 1, 1.0).unwrap_err();
        assert!(e.to_string().contains("line 3"), "{e}");
    }
}
