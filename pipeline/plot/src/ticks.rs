//! Tick labels for real-valued axes. plotters prints every tick with at least one decimal
//! (`100.0`, `80.0`), which clutters percentage axes such as those of 000 Fig. 7; labels here
//! carry just the decimals that the axis span calls for.

use std::ops::Range;

/// Labels ticks of an axis over `range` with the decimals its tick step needs. plotters
/// places at most ten ticks on an axis, spaced by 1, 2 or 5 times a power of ten, so the step
/// exceeds a ninth of the span; the decimals are those of the smallest such step (more
/// decimals would only add trailing zeros, fewer would print distinct ticks alike).
pub(super) fn tick_formatter(range: &Range<f64>) -> impl Fn(&f64) -> String {
    let bound = (range.end - range.start).abs() / 11.0;
    let decimals = if bound > 0.0 && bound.is_finite() {
        let power = bound.log10().floor();
        let step_power = if 5.0 * 10f64.powf(power) > bound {
            power
        } else {
            power + 1.0
        };
        (-step_power).max(0.0) as usize
    } else {
        0
    };
    let scale = 10f64.powi(decimals as i32);
    // Rounding first and then adding 0.0 prints a tick at -1e-17 or -0.0 as "0", not "-0".
    move |value: &f64| format!("{:.*}", decimals, (value * scale).round() / scale + 0.0)
}

#[cfg(test)]
mod tests {
    use super::tick_formatter;

    #[test]
    fn decimals_follow_the_span() {
        let percent = tick_formatter(&(-5.0..105.0));
        assert_eq!(percent(&100.0), "100");
        assert_eq!(percent(&-0.0), "0");
        let metres = tick_formatter(&(-0.5..0.5));
        assert_eq!(metres(&-1e-17), "0.0");
        assert_eq!(metres(&0.3), "0.3");
        let small = tick_formatter(&(0.0..0.5));
        assert_eq!(small(&0.25), "0.25");
        let unit = tick_formatter(&(0.0..3.0));
        assert_eq!(unit(&1.5), "1.5");
    }
}
