//! Time accounting by state: a unit is always in exactly one state, and the
//! clock adds the time spent in each. Totals over all states equal the
//! elapsed time exactly, in picoseconds (checked by the conservation tests).

use crate::engine::{Duration, Time};

/// Accumulates time per state for one unit. `N` is the number of states;
/// states are given as indices (`state as usize`).
///
/// A GPU idle until 2 ms, busy until 7 ms, idle again: at 10 ms it was busy
/// 5 ms and idle 5 ms, and the totals add up to the elapsed 10 ms.
///
/// ```
/// use rendersim_models::components::state_clock::StateClock;
/// use rendersim_engine::{Duration, Time};
///
/// const IDLE: usize = 0;
/// const BUSY: usize = 1;
/// let ms = |v| Time(Duration::ms(v).0);
/// let mut gpu = StateClock::<2>::new(IDLE);
/// assert_eq!(gpu.set(ms(2), BUSY), Duration::ms(2)); // 2 ms idle ended
/// assert_eq!(gpu.set(ms(2), BUSY), Duration::ZERO); // no change, nothing happens
/// assert_eq!(gpu.set(ms(7), IDLE), Duration::ms(5));
/// let totals = gpu.totals_at(ms(10));
/// assert_eq!(totals, [Duration::ms(5).0, Duration::ms(5).0]); // picoseconds
/// assert_eq!(totals.iter().sum::<u64>(), ms(10).0);
/// ```
#[derive(Debug, Clone)]
pub struct StateClock<const N: usize> {
    state: usize,
    since: Time,
    totals: [u64; N],
    /// Time moved between states by [`StateClock::transfer`] (two's
    /// complement: a state's total read is `totals + moved`).
    moved: [u64; N],
}

impl<const N: usize> StateClock<N> {
    /// A clock in `state` from time zero.
    pub fn new(state: usize) -> Self {
        assert!(state < N);
        StateClock {
            state,
            since: Time::ZERO,
            totals: [0; N],
            moved: [0; N],
        }
    }

    /// The current state.
    #[inline]
    pub fn state(&self) -> usize {
        self.state
    }

    /// When the current state began.
    #[inline]
    pub fn since(&self) -> Time {
        self.since
    }

    /// Moves to `state` at `now`; returns the time spent in the old state
    /// (zero if the state does not change, in which case nothing happens).
    #[inline(always)]
    pub fn set(&mut self, now: Time, state: usize) -> Duration {
        if state == self.state {
            return Duration::ZERO;
        }
        let spent = now.since(self.since);
        self.totals[self.state] += spent.0;
        self.state = state;
        self.since = now;
        spent
    }

    /// Closes the current interval at `now` without changing state (to
    /// split accounting at a frame boundary); returns its length.
    #[inline]
    pub fn split(&mut self, now: Time) -> Duration {
        let spent = now.since(self.since);
        self.totals[self.state] += spent.0;
        self.since = now;
        spent
    }

    /// Moves `amount` from state `from` to state `to` (for units whose
    /// split inside an interval is known only at its end). The amount must
    /// have been spent in `from` already, in the current interval or
    /// before: only totals read after the move see it, so it costs two
    /// additions, with no interval closed (a unit's draw at a time, at
    /// every draw's end, in a long run).
    #[inline]
    pub fn transfer(&mut self, from: usize, to: usize, amount: u64) {
        self.moved[from] = self.moved[from].wrapping_sub(amount);
        self.moved[to] = self.moved[to].wrapping_add(amount);
    }

    /// Totals per state as of `now` (the current state counted up to `now`).
    pub fn totals_at(&self, now: Time) -> [u64; N] {
        let mut t = self.totals;
        t[self.state] += now.since(self.since).0;
        for (t, m) in t.iter_mut().zip(self.moved) {
            debug_assert!(
                i128::from(*t) + i128::from(m as i64) >= 0,
                "more time moved out of a state than it had"
            );
            *t = t.wrapping_add(m);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals_sum_to_elapsed() {
        let mut c = StateClock::<3>::new(0);
        c.set(Time(10), 1);
        c.set(Time(10), 1);
        c.set(Time(25), 2);
        c.set(Time(40), 0);
        let t = c.totals_at(Time(100));
        assert_eq!(t, [10 + 60, 15, 15]);
        assert_eq!(t.iter().sum::<u64>(), 100);
    }

    #[test]
    fn transfers_move_time_between_states_and_keep_the_sum() {
        let mut c = StateClock::<3>::new(0);
        c.set(Time(40), 1);
        // 15 of state 0's 40 were idle, learned later; state 1 still runs.
        c.transfer(0, 2, 15);
        assert_eq!(c.totals_at(Time(50)), [25, 10, 15]);
        c.set(Time(60), 0);
        // Moved out of the running interval before it closed.
        c.transfer(0, 1, 5);
        assert_eq!(c.totals_at(Time(100)), [25 + 40 - 5, 20 + 5, 15]);
        assert_eq!(c.totals_at(Time(100)).iter().sum::<u64>(), 100);
    }
}
