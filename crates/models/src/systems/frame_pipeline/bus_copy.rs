//! A draw's copy over the bus the GPU's vertex fetch from AGP memory
//! shares (paper 000 §4.5.3, Table 4): when a scene has both
//! ([`super::workload::SceneProgram::bus_shared`]), the CPU thread copies
//! each draw's upload as a step of its own after the draw's other work, at
//! the rate the bus gives it ([`crate::components::shared_bus`]), and the
//! rate moves whenever a draw's fetch begins or ends. Without AGP
//! geometry the copy has the bus to itself, its time is fixed, and it stays
//! inside the draw's CPU time.
//!
//! [`BusCopy`] is the running copy: its rate now and its start. The CPU
//! thread owns it ([`super::cpu_thread::CpuThread::copy_turn`]).

use crate::components::shared_bus::SharedBus;
use crate::engine::{Duration, Time};

/// A running copy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BusCopy {
    /// Bytes per picosecond it gets now.
    rate: f64,
    /// When it began.
    began: Time,
}

impl BusCopy {
    /// Starts copying `bytes` at `now`, asking the bus for `alone` (bytes
    /// per picosecond, the rate into its memory); returns the copy and its
    /// time at the rate the bus gives it now.
    pub(super) fn begin(now: Time, bytes: u64, alone: f64, bus: &mut SharedBus) -> (BusCopy, Duration) {
        bus.set_copy(alone);
        let rate = bus.copy_rate();
        (BusCopy { rate, began: now }, Duration::from_ps_f64(bytes as f64 / rate))
    }

    /// The copy ended at `now`: the bus is left to the fetch; returns how
    /// long it took.
    pub(super) fn end(self, now: Time, bus: &mut SharedBus) -> Duration {
        bus.set_copy(0.0);
        now.since(self.began)
    }

    /// After the fetch's ask changed: the factor by which what is left of
    /// the copy lengthens (old rate / new rate), or `None` when its rate
    /// did not move.
    pub(super) fn retime(&mut self, bus: &SharedBus) -> Option<f64> {
        let rate = bus.copy_rate();
        if rate == self.rate {
            return None;
        }
        let factor = self.rate / rate;
        self.rate = rate;
        Some(factor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_copy_slows_while_a_fetch_shares_the_bus() {
        // 1 byte/ps bus; the copy asks all of it; 1000 bytes alone: 1000 ps.
        let mut bus = SharedBus::new(1.0);
        let (mut c, t) = BusCopy::begin(Time(0), 1000, 1.0, &mut bus);
        assert_eq!(t, Duration(1000));
        assert_eq!(c.retime(&bus), None);
        // A fetch asking for all of it: half each, the rest takes twice as long.
        bus.set_fetch(1.0);
        assert_eq!(c.retime(&bus), Some(2.0));
        bus.set_fetch(0.0);
        assert_eq!(c.retime(&bus), Some(0.5));
        assert_eq!(c.end(Time(1500), &mut bus), Duration(1500));
        assert_eq!(bus.copy_rate(), 0.0);
    }
}
