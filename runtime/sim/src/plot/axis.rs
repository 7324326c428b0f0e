//! Axes of the 2-D figures: tick positions at round values and plain tick labels chosen from
//! the axis range (`0`, `50`, `100`; `0.25`, `0.50`; `2e-8`, `4e-8` only where decimals would
//! need more than four places or the values reach 1e5), and a logarithmic axis for
//! non-negative quantities that span decades.

/// An axis: its range, where its ticks are and how they are labelled.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Lower end of the axis.
    pub lo: f64,
    /// Upper end of the axis.
    pub hi: f64,
    /// Tick positions, increasing, within `[lo, hi]`.
    pub ticks: Vec<f64>,
    /// Whether the axis is logarithmic (ticks at powers of ten).
    pub log: bool,
    /// Distance between ticks (linear axes).
    step: f64,
}

/// The smallest of `{1, 2, 2.5, 5} × 10^k` that is at least `span / intervals`.
fn nice_step(span: f64, intervals: usize) -> f64 {
    let raw = span / intervals.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if m * mag >= raw * (1.0 - 1e-9) {
            return m * mag;
        }
    }
    10.0 * mag
}

/// Decimal places that resolve multiples of `step` (`25` → 0, `0.5` → 1, `0.025` → 3).
fn decimals_of(step: f64) -> usize {
    let mut d = 0usize;
    while d < 15 {
        let scaled = step * 10f64.powi(d as i32);
        if (scaled - scaled.round()).abs() <= 1e-6 * scaled.abs().max(1.0) {
            return d;
        }
        d += 1;
    }
    d
}

/// `10^e`, the double nearest to it (`10f64.powi(-9)` is not exactly `1e-9`).
fn pow10(e: i32) -> f64 {
    format!("1e{e}").parse().unwrap_or(f64::NAN)
}

/// Removes trailing zeros of a mantissa in `1.50e-7` (→ `1.5e-7`, `2.0e-8` → `2e-8`).
fn trim_mantissa(s: &str) -> String {
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{e}")
        }
        _ => s.to_string(),
    }
}

impl Axis {
    /// A linear axis over `[lo, hi]` with at most `intervals` tick intervals, its ends moved out
    /// to the nearest ticks. An empty or non-finite range becomes `[0, 1]` (or a range around
    /// the single value).
    pub fn linear(lo: f64, hi: f64, intervals: usize) -> Axis {
        let (mut lo, mut hi) = if lo.is_finite() && hi.is_finite() && lo <= hi {
            (lo, hi)
        } else {
            (0.0, 1.0)
        };
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
            // A constant: 0 gets [0, 1], any other value ±10 % around it.
            let half = 0.1 * lo.abs();
            (lo, hi) = if lo == 0.0 {
                (0.0, 1.0)
            } else {
                (lo - half, hi + half)
            };
        }
        let step = nice_step(hi - lo, intervals);
        let first = (lo / step + 1e-9).floor();
        let last = (hi / step - 1e-9).ceil();
        let ticks: Vec<f64> = (0..=((last - first) as i64))
            .map(|k| {
                let v = (first + k as f64) * step;
                if v.abs() < step * 1e-9 {
                    0.0
                } else {
                    v
                }
            })
            .collect();
        Axis {
            lo: first * step,
            hi: last * step,
            ticks,
            log: false,
            step,
        }
    }

    /// An axis for a non-negative quantity (a norm, a distance, a manipulability): logarithmic
    /// (down to ten decades below the largest value at most) when its positive values span more
    /// than three decades, otherwise linear from 0.
    pub fn non_negative(values: impl IntoIterator<Item = f64>, intervals: usize) -> Axis {
        Self::non_negative_within(values, intervals, 3.0)
    }

    fn non_negative_within(
        values: impl IntoIterator<Item = f64>,
        intervals: usize,
        decades: f64,
    ) -> Axis {
        let (mut min_pos, mut max) = (f64::INFINITY, 0.0f64);
        for v in values.into_iter().filter(|v| v.is_finite()) {
            max = max.max(v);
            if v > 0.0 {
                min_pos = min_pos.min(v);
            }
        }
        if max > 0.0 && (max / min_pos).log10() > decades {
            // At most ten decades below the largest value: a first sample at 1e-17 would
            // otherwise squeeze the rest of the curve.
            Axis::logarithmic(min_pos.max(max * 1e-10), max)
        } else {
            Axis::linear(0.0, if max > 0.0 { max } else { 1.0 }, intervals)
        }
    }

    /// A logarithmic axis from the power of ten at or below `min` to the one at or above `max`
    /// (both positive), with a tick at every power of ten (every second or more beyond eight).
    pub fn logarithmic(min: f64, max: f64) -> Axis {
        let lo = min.log10().floor() as i32;
        let hi = (max.log10().ceil() as i32).max(lo + 1);
        let every = ((hi - lo) as usize).div_ceil(8).max(1);
        let ticks = (lo..=hi)
            .filter(|e| (e - lo) as usize % every == 0)
            .map(pow10)
            .collect();
        Axis {
            lo: pow10(lo),
            hi: pow10(hi),
            ticks,
            log: true,
            step: 0.0,
        }
    }

    /// The label of a tick: plain decimals with as many places as the tick spacing needs, or
    /// scientific notation without padding (`1e-5`, `2.5e-8`) where decimals would need more
    /// than four places or values reach 1e5.
    pub fn label(&self, v: f64) -> String {
        if self.log {
            let e = v.log10().round() as i32;
            return if (-3..=4).contains(&e) {
                let d = (-e).max(0) as usize;
                format!("{v:.d$}")
            } else {
                format!("1e{e}")
            };
        }
        let step = self.step;
        let v = if v.abs() < step * 1e-6 { 0.0 } else { v };
        let mag = self.lo.abs().max(self.hi.abs());
        let exponent = step.log10().floor() as i32;
        let decimals = decimals_of(step / 10f64.powi(exponent)) as i32 - exponent;
        if decimals <= 4 && mag < 1e5 {
            format!("{v:.prec$}", prec = decimals.max(0) as usize)
        } else if v == 0.0 {
            "0".to_string()
        } else {
            let e = v.abs().log10().floor() as i32;
            let prec = (e - exponent + decimals_of(step / 10f64.powi(exponent)) as i32).max(0);
            trim_mantissa(&format!("{v:.prec$e}", prec = prec as usize))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(a: &Axis) -> Vec<String> {
        a.ticks.iter().map(|&v| a.label(v)).collect()
    }

    #[test]
    fn time_axis_of_200_s_has_round_plain_labels() {
        let a = Axis::linear(0.0, 200.0, 8);
        assert_eq!((a.lo, a.hi), (0.0, 200.0));
        assert_eq!(
            labels(&a),
            ["0", "25", "50", "75", "100", "125", "150", "175", "200"]
        );
    }

    #[test]
    fn time_axis_of_10_s() {
        let a = Axis::linear(0.0, 10.0, 8);
        assert_eq!(labels(&a), ["0", "2", "4", "6", "8", "10"]);
    }

    #[test]
    fn tiny_lengths_are_scientific_without_padding() {
        let a = Axis::linear(0.0, 1e-7, 5);
        assert_eq!(
            labels(&a),
            ["0", "2e-8", "4e-8", "6e-8", "8e-8", "1e-7"],
            "{a:?}"
        );
        let a = Axis::linear(0.0, 2.3e-5, 5);
        assert_eq!(
            labels(&a),
            ["0", "5e-6", "1e-5", "1.5e-5", "2e-5", "2.5e-5"]
        );
    }

    #[test]
    fn fractions_get_the_places_their_spacing_needs() {
        let a = Axis::linear(-0.42, 0.9, 6);
        assert_eq!(
            labels(&a),
            ["-0.50", "-0.25", "0.00", "0.25", "0.50", "0.75", "1.00"]
        );
        let a = Axis::linear(0.0, 0.0123, 5);
        assert_eq!(
            labels(&a),
            ["0.0000", "0.0025", "0.0050", "0.0075", "0.0100", "0.0125"]
        );
    }

    #[test]
    fn no_stray_tick_near_zero() {
        // 0.1 * 3 - 0.3 is 5.6e-17, not zero: the tick at zero must read 0.
        let a = Axis::linear(-0.3, 0.3000000000000001, 6);
        assert!(a.ticks.contains(&0.0), "{a:?}");
        assert!(labels(&a).iter().all(|l| !l.contains('e')), "{a:?}");
    }

    #[test]
    fn large_values_are_scientific() {
        let a = Axis::linear(0.0, 3.0e6, 6);
        assert_eq!(
            labels(&a),
            ["0", "5e5", "1e6", "1.5e6", "2e6", "2.5e6", "3e6"]
        );
    }

    #[test]
    fn norms_start_at_zero_or_go_logarithmic() {
        let a = Axis::non_negative([0.02, 0.5, 0.3], 5);
        assert_eq!(a.lo, 0.0);
        assert!(!a.log);
        let a = Axis::non_negative([1e-9, 1e-3, 0.02, 0.0], 5);
        assert!(a.log);
        assert_eq!((a.lo, a.hi), (1e-9, 0.1));
        assert_eq!(
            labels(&a),
            ["1e-9", "1e-8", "1e-7", "1e-6", "1e-5", "1e-4", "0.001", "0.01", "0.1"]
        );
        // All zero: a plain axis from 0, not a negative one.
        let a = Axis::non_negative([0.0, 0.0], 5);
        assert_eq!(a.lo, 0.0);
        assert!(a.hi > 0.0);
        // A first sample at 1e-20 does not stretch the axis beyond ten decades.
        let a = Axis::non_negative([1e-20, 1e-9, 1e-7], 5);
        assert!(a.log && a.lo >= 1e-18 && a.hi == 1e-7, "{a:?}");
    }

    #[test]
    fn a_constant_keeps_a_range() {
        let a = Axis::linear(0.42, 0.42, 5);
        assert!(a.lo < 0.42 && a.hi > 0.42, "{a:?}");
        let a = Axis::linear(0.0, 0.0, 5);
        assert_eq!(a.lo, 0.0);
        assert!(a.hi > 0.0);
    }
}
