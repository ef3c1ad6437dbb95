//! A unified shader-core pool shared by two work streams, vertex and
//! fragment shading (the unified-shader GPUs that followed paper 000's
//! GeForce3: one array of programmable cores runs both kinds of work, while
//! fixed-function units keep their own rates).
//!
//! Each stream serves one item at a time. An item has a *shader* part, which
//! needs the pool, and a *fixed-function* part (index fetch and triangle
//! setup for vertices, early depth test and blending for fragments), which
//! runs beside it on its own unit: the item ends when both are done.
//! Shader work is given as the time it takes with the whole pool. When both
//! streams have shader work, the pool's `cores` are divided by the
//! [`Scheduling`] policy, so a stream holding `k` of `n` cores progresses at
//! `k / n` of full speed; an idle stream's cores go to the other one
//! (except under [`Scheduling::Reserved`]). The pool is work-conserving:
//! while either stream has shader work, no core idles, so the shader work
//! of vertex and fragment items adds up, which is why pass times on a
//! unified GPU are close to the sum of the two terms rather than their
//! maximum (measured on an NVIDIA H200, `docs/measurements/nvidia-h200/`).
//!
//! Progress is tracked exactly in integers: one picosecond of whole-pool
//! work is `2 * cores` work units, so a fair half of an odd core count is
//! still a whole number of units per picosecond. Streams start and end
//! items with [`ShaderPool::begin`] and [`ShaderPool::end`]; once everything
//! that happens at one instant is done, [`ShaderPool::settle`] applies the
//! policy and returns the completions that moved, each with a fresh tag, so
//! the caller can ignore completion events whose tag is stale.

use crate::engine::{Duration, Time, TimeError};

/// The two streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// Vertex shading (the geometry stage's programmable part).
    Vertex = 0,
    /// Fragment shading (the fragment stage's programmable part).
    Fragment = 1,
}

/// How the pool's cores are divided while both streams have shader work.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheduling {
    /// Half each (processor sharing).
    Fair,
    /// Vertex work takes every core; fragments run only in its gaps.
    VertexFirst,
    /// Fragment work takes every core; vertices run only in its gaps.
    FragmentFirst,
    /// `vertex_cores` cores serve only vertices, the rest only fragments,
    /// even when the other stream is idle: a split pipeline built from the
    /// same cores (no borrowing).
    Reserved {
        /// Cores held for vertex work (1 ..= cores - 1).
        vertex_cores: u32,
    },
}

/// A completion to schedule: `stream`'s item ends at `at`; the event
/// carries `tag`, checked with [`ShaderPool::is_current`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Due {
    /// Which stream.
    pub stream: Stream,
    /// When its item ends.
    pub at: Time,
    /// The tag the completion event must carry.
    pub tag: u32,
}

/// The completions to (re)schedule after a change: at most one per stream.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Changes(pub [Option<Due>; 2]);

impl Changes {
    /// The completions, vertex stream first.
    pub fn iter(&self) -> impl Iterator<Item = Due> + '_ {
        self.0.iter().flatten().copied()
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    active: bool,
    /// Shader work left, in work units.
    remaining: u128,
    /// Work units per picosecond now.
    rate: u64,
    /// When `remaining` was last brought up to date.
    since: Time,
    /// When the item's fixed-function part ends.
    fixed_end: Time,
    /// The scheduled completion, if any.
    due: Option<Time>,
    tag: u32,
}

/// The pool: `cores` cores, a policy, and the item each stream serves.
///
/// A vertex item of 10 us of whole-pool work starts alone at 0; at 4 us a
/// fragment item of 3 us arrives and the fair policy halves each stream's
/// speed. The fragment item ends at 10 us (3 us of work at half speed), the
/// vertex item, alone again, at 13 us: the work adds up, 10 + 3.
///
/// ```
/// use rendersim_models::components::shader_pool::{Scheduling, ShaderPool, Stream};
/// use rendersim_engine::{Duration, Time};
///
/// let us = |v| Time(Duration::us(v).0);
/// let mut pool = ShaderPool::new(4, Scheduling::Fair);
/// pool.begin(us(0), Stream::Vertex, Duration::us(10), Duration::ZERO).unwrap();
/// let due: Vec<_> = pool.settle(us(0)).unwrap().iter().map(|d| (d.stream, d.at)).collect();
/// assert_eq!(due, [(Stream::Vertex, us(10))]);
///
/// pool.begin(us(4), Stream::Fragment, Duration::us(3), Duration::ZERO).unwrap();
/// let due: Vec<_> = pool.settle(us(4)).unwrap().iter().map(|d| (d.stream, d.at)).collect();
/// // Vertex: 6 us of work left at half speed; fragment: 3 us at half speed.
/// assert_eq!(due, [(Stream::Vertex, us(16)), (Stream::Fragment, us(10))]);
///
/// pool.end(us(10), Stream::Fragment);
/// let moved = pool.settle(us(10)).unwrap();
/// let vertex = moved.iter().next().unwrap();
/// assert_eq!((vertex.stream, vertex.at), (Stream::Vertex, us(13)));
/// assert!(pool.is_current(Stream::Vertex, vertex.tag)); // the 16 us event is stale
/// pool.end(us(13), Stream::Vertex);
/// assert_eq!(pool.work_done(), Duration::us(13));
/// ```
#[derive(Debug, Clone)]
pub struct ShaderPool {
    cores: u64,
    policy: Scheduling,
    slots: [Slot; 2],
    /// Core-picoseconds of shader work done so far (for utilisation).
    done_units: u128,
    /// An item began or ended since the last [`ShaderPool::settle`].
    dirty: bool,
}

impl ShaderPool {
    /// A pool of `cores` (at least 1) cores under `policy`.
    pub fn new(cores: u32, policy: Scheduling) -> Self {
        ShaderPool {
            cores: u64::from(cores.max(1)),
            policy,
            slots: [Slot::default(); 2],
            done_units: 0,
            dirty: false,
        }
    }

    /// Work units per picosecond of whole-pool time.
    fn full(&self) -> u64 {
        2 * self.cores
    }

    /// Whether `stream` is serving an item.
    pub fn active(&self, stream: Stream) -> bool {
        self.slots[stream as usize].active
    }

    /// Whether a completion carrying `tag` is the current one of `stream`.
    pub fn is_current(&self, stream: Stream, tag: u32) -> bool {
        let s = &self.slots[stream as usize];
        s.active && s.tag == tag
    }

    /// Shader work done so far, as picoseconds of the whole pool.
    pub fn work_done(&self) -> Duration {
        Duration((self.done_units / u128::from(self.full())) as u64)
    }

    /// `stream` starts an item: `shader` of whole-pool work and `fixed` of
    /// fixed-function time beside it. Call [`ShaderPool::settle`] after the
    /// instant's changes.
    pub fn begin(&mut self, now: Time, stream: Stream, shader: Duration, fixed: Duration) -> Result<(), TimeError> {
        self.advance(now);
        let full = self.full();
        let s = &mut self.slots[stream as usize];
        debug_assert!(!s.active, "{stream:?} started an item while serving one");
        s.active = true;
        s.remaining = u128::from(shader.0) * u128::from(full);
        s.since = now;
        s.fixed_end = now.add(fixed, "fixed-function part of a shader item")?;
        s.due = None;
        s.rate = 0;
        self.dirty = true;
        Ok(())
    }

    /// `stream`'s item ended (its current completion fired). Call
    /// [`ShaderPool::settle`] after the instant's changes.
    #[inline(never)]
    pub fn end(&mut self, now: Time, stream: Stream) {
        self.advance(now);
        let s = &mut self.slots[stream as usize];
        s.active = false;
        s.remaining = 0;
        s.rate = 0;
        s.due = None;
        self.dirty = true;
    }

    /// Brings each active stream's remaining work up to `now`.
    fn advance(&mut self, now: Time) {
        for s in self.slots.iter_mut().filter(|s| s.active) {
            let dt = u128::from(now.0.saturating_sub(s.since.0));
            let did = (dt * u128::from(s.rate)).min(s.remaining);
            s.remaining -= did;
            self.done_units += did;
            s.since = now;
        }
    }

    /// The rates the policy gives the streams now.
    fn rates(&self) -> [u64; 2] {
        let full = self.full();
        let wants = |st: Stream| {
            let s = &self.slots[st as usize];
            s.active && s.remaining > 0
        };
        let (v, f) = (wants(Stream::Vertex), wants(Stream::Fragment));
        let alone = |x: bool| if x { full } else { 0 };
        match self.policy {
            Scheduling::Reserved { vertex_cores } => {
                let k = u64::from(vertex_cores).min(self.cores);
                [if v { 2 * k } else { 0 }, if f { full - 2 * k } else { 0 }]
            }
            _ if !(v && f) => [alone(v), alone(f)],
            Scheduling::Fair => [self.cores, self.cores],
            Scheduling::VertexFirst => [full, 0],
            Scheduling::FragmentFirst => [0, full],
        }
    }

    /// Applies the policy's rates at `now` and returns the completions that
    /// moved (a started item's always).
    pub fn settle(&mut self, now: Time) -> Result<Changes, TimeError> {
        if !self.dirty {
            return Ok(Changes::default());
        }
        self.dirty = false;
        self.advance(now);
        let rates = self.rates();
        let mut changes = Changes::default();
        for (i, s) in self.slots.iter_mut().enumerate() {
            if !s.active {
                continue;
            }
            s.rate = rates[i];
            let shader_end = if s.remaining == 0 {
                Some(now)
            } else if s.rate == 0 {
                None
            } else {
                let ps = match u64::try_from(s.remaining) {
                    // The common case without 128-bit division.
                    Ok(r) => u128::from(r.div_ceil(s.rate)),
                    Err(_) => s.remaining.div_ceil(u128::from(s.rate)),
                };
                let t = u128::from(now.0) + ps;
                let t = u64::try_from(t).map_err(|_| TimeError::Overflow {
                    context: "a shader item on the unified pool".into(),
                    at: now,
                    by: Duration(u64::try_from(ps).unwrap_or(u64::MAX)),
                })?;
                Some(Time(t))
            };
            let due = shader_end.map(|t| t.max(s.fixed_end));
            if due != s.due {
                s.due = due;
                if let Some(at) = due {
                    s.tag = s.tag.wrapping_add(1);
                    let stream = if i == 0 { Stream::Vertex } else { Stream::Fragment };
                    changes.0[i] = Some(Due { stream, at, tag: s.tag });
                } else {
                    // Waiting for cores: any completion in flight is stale.
                    s.tag = s.tag.wrapping_add(1);
                }
            }
        }
        Ok(changes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(ps: u64) -> Time {
        Time(ps)
    }

    fn start(p: &mut ShaderPool, at: u64, st: Stream, shader: u64, fixed: u64) -> Changes {
        p.begin(t(at), st, Duration(shader), Duration(fixed)).unwrap();
        p.settle(t(at)).unwrap()
    }

    fn finish(p: &mut ShaderPool, at: u64, st: Stream) -> Changes {
        p.end(t(at), st);
        p.settle(t(at)).unwrap()
    }

    #[test]
    fn alone_a_stream_gets_the_whole_pool() {
        let mut p = ShaderPool::new(4, Scheduling::Fair);
        let c = start(&mut p, 0, Stream::Vertex, 100, 10);
        assert_eq!(c.0[0].map(|d| d.at), Some(t(100)));
    }

    #[test]
    fn fixed_function_part_can_dominate() {
        let mut p = ShaderPool::new(4, Scheduling::Fair);
        let c = start(&mut p, 5, Stream::Fragment, 10, 50);
        assert_eq!(c.0[1].map(|d| d.at), Some(t(55)));
    }

    #[test]
    fn fair_sharing_adds_the_work_up() {
        // 100 ps of vertex and 100 ps of fragment work, started together:
        // both at half speed, both end at 200 (the sum, not the max).
        let mut p = ShaderPool::new(3, Scheduling::Fair);
        p.begin(t(0), Stream::Vertex, Duration(100), Duration::ZERO).unwrap();
        let c = start(&mut p, 0, Stream::Fragment, 100, 0);
        let ats: Vec<_> = c.iter().map(|d| (d.stream, d.at)).collect();
        assert_eq!(ats, vec![(Stream::Vertex, t(200)), (Stream::Fragment, t(200))]);
        p.end(t(200), Stream::Vertex);
        assert_eq!(finish(&mut p, 200, Stream::Fragment), Changes::default());
        assert_eq!(p.work_done(), Duration(200));
    }

    #[test]
    fn a_stream_speeds_up_when_the_other_ends() {
        let mut p = ShaderPool::new(2, Scheduling::Fair);
        start(&mut p, 0, Stream::Vertex, 50, 0);
        let c = start(&mut p, 0, Stream::Fragment, 200, 0);
        assert_eq!(c.0[0].unwrap().at, t(100));
        let stale = c.0[1].unwrap();
        // Vertex ends at 100; fragment has done 50 and gets the whole pool.
        let c = finish(&mut p, 100, Stream::Vertex);
        let f = c.0[1].unwrap();
        assert_eq!(f.at, t(250));
        assert!(!p.is_current(Stream::Fragment, stale.tag));
        assert!(p.is_current(Stream::Fragment, f.tag));
    }

    #[test]
    fn an_unchanged_completion_is_not_rescheduled() {
        let mut p = ShaderPool::new(2, Scheduling::Fair);
        start(&mut p, 0, Stream::Vertex, 50, 0);
        start(&mut p, 0, Stream::Fragment, 50, 0);
        // Both end at 100 and the next items start at once: nothing moves
        // for a stream that was not touched.
        p.end(t(100), Stream::Vertex);
        p.begin(t(100), Stream::Vertex, Duration(10), Duration::ZERO).unwrap();
        let c = p.settle(t(100)).unwrap();
        // The fragment item has no shader work left, so vertex work has the
        // whole pool; the fragment completion at 100 stands.
        assert_eq!(c.0[0].map(|d| d.at), Some(t(110)));
        assert_eq!(c.0[1], None);
    }

    #[test]
    fn priority_starves_the_other_stream_until_it_is_done() {
        let mut p = ShaderPool::new(8, Scheduling::VertexFirst);
        start(&mut p, 0, Stream::Fragment, 100, 0);
        let c = start(&mut p, 10, Stream::Vertex, 30, 0);
        assert_eq!(c.0[0].map(|d| d.at), Some(t(40)));
        assert_eq!(c.0[1], None, "fragment waits without a completion");
        let c = finish(&mut p, 40, Stream::Vertex);
        assert_eq!(c.0[1].map(|d| d.at), Some(t(130)));
    }

    #[test]
    fn reserved_cores_do_not_borrow() {
        // 1 of 4 cores for vertices: alone, vertex work runs at a quarter.
        let mut p = ShaderPool::new(4, Scheduling::Reserved { vertex_cores: 1 });
        let c = start(&mut p, 0, Stream::Vertex, 100, 0);
        assert_eq!(c.0[0].map(|d| d.at), Some(t(400)));
        let c = start(&mut p, 0, Stream::Fragment, 300, 0);
        assert_eq!(c.0[1].map(|d| d.at), Some(t(400)));
        assert_eq!(c.0[0], None, "the vertex completion did not move");
    }

    #[test]
    fn odd_core_counts_share_exactly() {
        let mut p = ShaderPool::new(1, Scheduling::Fair);
        p.begin(t(0), Stream::Vertex, Duration(7), Duration::ZERO).unwrap();
        let c = start(&mut p, 0, Stream::Fragment, 7, 0);
        assert_eq!(c.0[0].map(|d| d.at), Some(t(14)));
    }

    #[test]
    fn huge_work_overflows_cleanly() {
        let mut p = ShaderPool::new(64, Scheduling::Fair);
        p.begin(Time(u64::MAX - 5), Stream::Vertex, Duration(100), Duration::ZERO)
            .unwrap();
        assert!(matches!(p.settle(Time(u64::MAX - 5)), Err(TimeError::Overflow { .. })));
        let mut p = ShaderPool::new(64, Scheduling::Fair);
        assert!(
            p.begin(Time(u64::MAX - 5), Stream::Vertex, Duration(1), Duration(100))
                .is_err()
        );
    }
}
