//! Where a frame flipped without waiting for the vertical blank tears the
//! picture (`immediate`, or vsync off).
//!
//! A display scans each refresh out line by line, top to bottom, then rests
//! for the vertical blanking interval. A flip that lands while the panel
//! scans switches the image mid-picture: the lines above the scan position
//! show the old frame and the lines below the new one, and the boundary is
//! the tear line. A flip during the blanking interval shows whole (this is
//! when a vsync'd flip happens). The model is the standard video timing:
//! each refresh period `P` (vertical blanks at `k * P` from time zero, the
//! grid a fixed-refresh display keeps) begins with its blanking interval,
//! a share `display.blanking` of the period, and scans the active lines
//! evenly over the rest. A flip at phase `t mod P` in the active part tears
//! at the fraction `(t mod P - b P) / ((1 - b) P)` of the picture height
//! from the top.
//!
//! The default share, 0.04, is the 1920x1080 60 Hz timing of CTA-861 (1125
//! lines in all, 1080 active: 45 / 1125). Reduced-blanking timings (VESA
//! CVT-RB) leave less, about 2.8% at 1080p60 (460 us of 16.7 ms); `0` makes
//! every flip off the grid tear.
//!
//! ```
//! use rendersim_models::components::tearing::ScanOut;
//! use rendersim_engine::{Duration, Time};
//!
//! // 16 ms refreshes, 4% blanking (0.64 ms): a flip 8 ms in tears at
//! // (8 - 0.64) / 15.36 of the height, a flip at the vertical blank does not.
//! let scan = ScanOut::new(Duration::ms(16), 0.04);
//! let y = scan.tear_line(Time(8_000_000_000)).unwrap();
//! assert!((y - 7.36 / 15.36).abs() < 1e-12);
//! assert_eq!(scan.tear_line(Time(32_000_000_000)), None);
//! assert_eq!(scan.tear_line(Time(32_500_000_000)), None); // still blanking
//! ```

use crate::engine::{Duration, Time};

/// The share of a refresh spent in vertical blanking unless a model says
/// otherwise (CTA-861 1080p60: 45 of 1125 lines).
pub const DEFAULT_BLANKING: f64 = 0.04;

/// A fixed refresh's scan-out: its period and blanking interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanOut {
    period: u64,
    blank: u64,
}

impl ScanOut {
    /// Refreshes of `period` whose first `blanking` share is the vertical
    /// blanking interval (`0 <= blanking < 1`, checked by the display's
    /// configuration).
    pub fn new(period: Duration, blanking: f64) -> Self {
        let period = period.0.max(1);
        let blank = ((period as f64) * blanking.clamp(0.0, 1.0)).round() as u64;
        ScanOut {
            period,
            blank: blank.min(period - 1),
        }
    }

    /// Where a flip at `t` tears the picture: the fraction of its height
    /// from the top (0 to 1), or `None` when the flip lands in the vertical
    /// blanking interval and the frame shows whole.
    pub fn tear_line(&self, t: Time) -> Option<f64> {
        let phase = t.0 % self.period;
        (phase >= self.blank).then(|| (phase - self.blank) as f64 / (self.period - self.blank) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flip_tears_where_the_scan_is_and_not_in_the_blanking() {
        let s = ScanOut::new(Duration(1000), 0.1);
        assert_eq!(s.tear_line(Time(0)), None);
        assert_eq!(s.tear_line(Time(99)), None);
        assert_eq!(s.tear_line(Time(100)), Some(0.0));
        assert_eq!(s.tear_line(Time(550)), Some(0.5));
        assert_eq!(s.tear_line(Time(1999)), Some(899.0 / 900.0));
        let none = ScanOut::new(Duration(1000), 0.0);
        assert_eq!(none.tear_line(Time(5000)), Some(0.0));
        assert_eq!(none.tear_line(Time(5250)), Some(0.25));
    }
}
