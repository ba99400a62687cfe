//! Tick labels for real-valued axes. plotters prints every tick with at least one decimal
//! (`100.0`, `80.0`), which clutters percentage axes such as those of 000 Fig. 7; labels here
//! carry just the decimals that the axis span calls for.

use std::ops::Range;

/// Labels ticks of an axis over `range` with as many decimals as about ten ticks need.
pub(super) fn tick_formatter(range: &Range<f64>) -> impl Fn(&f64) -> String {
    let step = (range.end - range.start).abs() / 10.0;
    let decimals = if step > 0.0 {
        (-step.log10()).ceil().max(0.0) as usize
    } else {
        0
    };
    // Adding 0.0 turns a -0.0 tick into 0.0, so that it is not printed as "-0".
    move |value: &f64| format!("{:.*}", decimals, value + 0.0)
}

#[cfg(test)]
mod tests {
    use super::tick_formatter;

    #[test]
    fn decimals_follow_the_span() {
        let percent = tick_formatter(&(-5.0..105.0));
        assert_eq!(percent(&100.0), "100");
        assert_eq!(percent(&-0.0), "0");
        let small = tick_formatter(&(0.0..0.5));
        assert_eq!(small(&0.25), "0.25");
        let unit = tick_formatter(&(0.0..3.0));
        assert_eq!(unit(&1.5), "1.5");
    }
}
