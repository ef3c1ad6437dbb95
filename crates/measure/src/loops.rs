//! The loop-count search of the timed studies: a shader ALU loop count at
//! which the term a study tests takes at least a target time on the device
//! (on a GPU the same meshes need thousands of times more shader work than
//! on lavapipe). The search reports the loop count it settled on and the
//! time it measured there, never the target it aimed at; when no count up to
//! [`MAX_LOOPS`] reaches the target it says it fell short.
//!
//! The search only calls a cost function, so it is tested here on synthetic
//! devices; `studies.rs` hands it passes measured on a real one.

use serde::Serialize;

/// The largest loop count the search tries (4,194,304: 62 times the 67,390
/// vertex-shader loops that take 19 ms on a 96x96 grid on an NVIDIA H200).
pub const MAX_LOOPS: u32 = 1 << 22;

/// Cost measurements the search makes at most.
pub const MAX_TRIES: u32 = 8;

/// The most one step multiplies or divides the loop count by, so that a
/// noisy cost near zero does not send the search to [`MAX_LOOPS`] at once.
const MAX_STEP: f64 = 100.0;

/// Where a search ended: the loop count used and the cost measured at it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopSearch {
    /// The time aimed at, ms (at least this; at most 1.5 times it).
    pub target_ms: f64,
    /// The loop count the study uses.
    pub loops: u32,
    /// The cost measured at `loops` during the search, ms.
    pub reached_ms: f64,
    /// Cost measurements made.
    pub tries: u32,
}

impl LoopSearch {
    /// Whether the cost at `loops` reached the target.
    pub fn reached(&self) -> bool {
        self.reached_ms >= self.target_ms
    }

    /// The search's outcome in words: `"N loops (OUTCOME)"`, see
    /// [`LoopSearch::outcome`].
    pub fn describe(&self, what: &str) -> String {
        format!("{} loops ({})", self.loops, self.outcome(what))
    }

    /// `"WHAT took X ms there, target at least T ms"` when the target was
    /// reached, else [`LoopSearch::shortfall`].
    pub fn outcome(&self, what: &str) -> String {
        if self.reached() {
            format!(
                "{what} took {} ms there, target at least {} ms",
                ms(self.reached_ms),
                ms(self.target_ms)
            )
        } else {
            self.shortfall()
        }
    }

    /// `"fell short: reached X ms at N loops (target T ms)"`.
    pub fn shortfall(&self) -> String {
        format!(
            "fell short: reached {} ms at {} loops (target {} ms)",
            ms(self.reached_ms),
            self.loops,
            ms(self.target_ms)
        )
    }
}

/// Milliseconds to three decimals, without trailing zeros (`15`, `19.01`).
fn ms(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Searches a loop count whose `cost` (ns, growing with the loops) lies
/// between `target_ns` and 1.5 times it: from `start`, each try rescales the
/// count by target / cost, aiming 20% above the target (a step multiplies or
/// divides by at most 100), within 1..=[`MAX_LOOPS`], at most [`MAX_TRIES`]
/// measurements. Returns a count that was measured: the first in the range;
/// else the smallest that reached the target; else the one that came
/// closest (the largest tried), which then fell short.
pub fn search_loops<E>(
    start: u32,
    target_ns: f64,
    mut cost: impl FnMut(u32) -> Result<f64, E>,
) -> Result<LoopSearch, E> {
    let mut loops = start.clamp(1, MAX_LOOPS);
    let mut tried: Vec<(u32, f64)> = Vec::new();
    for _ in 0..MAX_TRIES {
        let c = cost(loops)?;
        tried.push((loops, c));
        if c >= target_ns && c <= 1.5 * target_ns {
            break;
        }
        let here = f64::from(loops);
        let next = if c > 0.0 {
            (here * 1.2 * target_ns / c).ceil()
        } else {
            here * MAX_STEP
        };
        let next = next
            .clamp(here / MAX_STEP, here * MAX_STEP)
            .clamp(1.0, f64::from(MAX_LOOPS))
            .round() as u32;
        if next == loops || tried.iter().any(|&(l, _)| l == next) {
            break;
        }
        loops = next;
    }
    let in_range = tried.iter().find(|(_, c)| *c >= target_ns && *c <= 1.5 * target_ns);
    let reached = tried.iter().filter(|(_, c)| *c >= target_ns).min_by_key(|(l, _)| *l);
    let closest = tried.iter().max_by_key(|(l, _)| *l);
    let &(loops, c) = in_range
        .or(reached)
        .or(closest)
        .expect("MAX_TRIES >= 1: at least one cost was measured");
    Ok(LoopSearch {
        target_ms: target_ns / 1e6,
        loops,
        reached_ms: c / 1e6,
        tries: tried.len() as u32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic device: the cost of a count, and every count it was asked for.
    fn search(start: u32, target_ms: f64, f: impl Fn(u32) -> f64) -> (LoopSearch, Vec<u32>) {
        let mut asked = Vec::new();
        let s = search_loops::<()>(start, target_ms * 1e6, |l| {
            asked.push(l);
            Ok(f(l))
        })
        .unwrap();
        (s, asked)
    }

    #[test]
    fn a_linear_device_is_found_and_the_measured_cost_reported() {
        // The H200's vertex shader on grid:96x96: 19.0 ms at 67,390 loops.
        let ns_per_loop = 19.0e6 / 67390.0;
        let (s, asked) = search(1000, 15.0, |l| ns_per_loop * f64::from(l));
        assert!(s.reached() && s.reached_ms >= 15.0 && s.reached_ms <= 22.5, "{s:?}");
        assert_eq!(s.reached_ms, ns_per_loop * f64::from(s.loops) / 1e6);
        assert_eq!(*asked.last().unwrap(), s.loops);
        assert!(s.tries <= 3, "{asked:?}");
        assert!(
            s.describe("geometry alone")
                .contains(&format!("{} loops (geometry alone took", s.loops))
        );
    }

    #[test]
    fn the_h4_case_reaches_its_target() {
        // H4 on the H200 ran at 300 loops: 0.153 ms against a 10 ms target.
        let (s, _) = search(300, 10.0, |l| 0.009e6 + 0.48e3 * f64::from(l));
        assert!(s.reached() && s.loops > 10_000, "{s:?}");
    }

    #[test]
    fn a_slow_device_is_searched_downwards() {
        let (s, _) = search(5000, 5.0, |l| 10_000.0 * f64::from(l));
        assert!(s.reached() && s.reached_ms <= 7.5, "{s:?}");
        assert!(s.loops < 5000);
    }

    #[test]
    fn a_device_that_saturates_falls_short_and_says_so() {
        // The cost stops growing at 2 ms: no count reaches 10 ms.
        let (s, asked) = search(100, 10.0, |l| (1000.0 * f64::from(l)).min(2.0e6));
        assert!(!s.reached(), "{s:?}");
        assert_eq!(s.loops, *asked.iter().max().unwrap());
        assert!(asked.len() as u32 <= MAX_TRIES);
        let text = s.describe("geometry alone");
        assert!(
            text.contains(&format!("fell short: reached 2 ms at {} loops (target 10 ms)", s.loops)),
            "{text}"
        );
    }

    #[test]
    fn a_cost_of_zero_is_searched_up_to_the_bound_in_bounded_steps() {
        let (s, asked) = search(1, 1.0, |_| 0.0);
        assert!(!s.reached());
        for w in asked.windows(2) {
            assert!(f64::from(w[1]) <= f64::from(w[0]) * MAX_STEP, "{asked:?}");
        }
        assert!(asked.iter().all(|&l| l <= MAX_LOOPS));
        assert_eq!(s.reached_ms, 0.0);
    }

    #[test]
    fn a_count_beyond_the_bound_is_capped_and_reported_short() {
        // Would need 10 million loops.
        let (s, asked) = search(1_000_000, 10.0, f64::from);
        assert_eq!(s.loops, MAX_LOOPS, "{asked:?}");
        assert!(!s.reached() && (s.reached_ms - f64::from(MAX_LOOPS) / 1e6).abs() < 1e-9);
    }

    #[test]
    fn an_overshoot_keeps_the_smallest_count_that_reached() {
        // Steps in the cost (a noisy device): 1 ms below 1000 loops, 40 ms from there.
        let (s, _) = search(10, 10.0, |l| if l < 1000 { 1.0e6 } else { 40.0e6 });
        assert!(s.reached() && s.reached_ms == 40.0, "{s:?}");
    }

    #[test]
    fn errors_of_the_device_are_passed_on() {
        let e = search_loops(10, 1e6, |_| Err::<f64, &str>("lost")).unwrap_err();
        assert_eq!(e, "lost");
    }
}
