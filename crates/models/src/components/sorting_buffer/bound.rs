//! What the best offline strategy can do: a lower bound for any sequence,
//! and the exact optimum for tiny ones (paper 001, slide "c-competitive":
//! online strategies are measured against the optimal offline strategy,
//! which knows the whole sequence but must use the same buffer).
//!
//! **The lower bound.** For a sequence with D distinct states and a buffer
//! of K slots,
//!
//! ```text
//! lower_bound = D + max(0, max_t S(t) - K)
//! ```
//!
//! where S(t) counts the states that occur both at or before position t and
//! after it ("open" at t). Why no strategy, offline included, does better:
//! every state is sent at least once (D). Look at the moment after element t
//! has been handled. The buffer then holds at most K - 1 elements (a full
//! buffer must be emptied before the next element is written), so at least
//! S(t) - (K - 1) open states have no element buffered: every element of
//! theirs seen so far was already sent, and the element still to come must
//! be sent later, in another run, unless the two runs join, which needs
//! that state to be the last one sent before the moment and the first one
//! after it. At most one state can be that, so at least S(t) - K states
//! are sent in two runs or more. Taking the t with the largest S(t) gives
//! the bound. `tests/it/sortbuf.rs` checks it against an exhaustive search.
//!
//! **The exact optimum** ([`offline_optimum`]) searches every strategy
//! (sending any buffered state at any time, not only on overflow) by
//! memoized depth-first search over (position, buffer contents, last
//! state), for sequences of at most [`MAX_OFFLINE_LEN`] elements.

use std::collections::HashMap;

use super::{SortBufferError, StateId, check_buffer};

/// Longest sequence [`offline_optimum`] searches.
pub const MAX_OFFLINE_LEN: usize = 12;

/// The lower bound of the offline optimum (see the module).
pub fn lower_bound(seq: &[StateId], k: usize) -> u64 {
    let mut first: HashMap<StateId, usize> = HashMap::new();
    let mut last: HashMap<StateId, usize> = HashMap::new();
    for (i, &s) in seq.iter().enumerate() {
        first.entry(s).or_insert(i);
        last.insert(s, i);
    }
    // S(t) = #{s : first(s) <= t < last(s)}.
    let mut delta = vec![0i64; seq.len() + 1];
    for (s, &f) in &first {
        let l = last[s];
        if l > f {
            delta[f] += 1;
            delta[l] -= 1;
        }
    }
    let (mut open, mut most) = (0i64, 0i64);
    for d in delta {
        open += d;
        most = most.max(open);
    }
    first.len() as u64 + (most - k as i64).max(0) as u64
}

struct Exact<'a> {
    seq: &'a [u8],
    k: usize,
    memo: HashMap<(u8, Vec<u8>, u8), u32>,
}

const NONE: u8 = u8::MAX;

impl Exact<'_> {
    /// Fewest further changes from position `i` with `buf` buffered
    /// (counts per state) and `last` the state sent last.
    fn best(&mut self, i: usize, buf: &mut Vec<u8>, last: u8) -> u32 {
        let held: usize = buf.iter().map(|&c| c as usize).sum();
        if i == self.seq.len() && held == 0 {
            return 0;
        }
        let key = (i as u8, buf.clone(), last);
        if let Some(&v) = self.memo.get(&key) {
            return v;
        }
        let mut best = u32::MAX;
        if i < self.seq.len() && held < self.k {
            let c = self.seq[i] as usize;
            buf[c] += 1;
            best = best.min(self.best(i + 1, buf, last));
            buf[c] -= 1;
        }
        for c in 0..buf.len() {
            if buf[c] > 0 {
                let n = buf[c];
                buf[c] = 0;
                let cost = u32::from(c as u8 != last) + self.best(i, buf, c as u8);
                buf[c] = n;
                best = best.min(cost);
            }
        }
        self.memo.insert(key, best);
        best
    }
}

/// The exact offline optimum of `seq` with `k` slots, by exhaustive search
/// (at most [`MAX_OFFLINE_LEN`] elements).
pub fn offline_optimum(seq: &[StateId], k: usize) -> Result<u64, SortBufferError> {
    check_buffer(k)?;
    if seq.len() > MAX_OFFLINE_LEN {
        return Err(SortBufferError::TooLongForExact {
            got: seq.len(),
            limit: MAX_OFFLINE_LEN,
        });
    }
    let mut ids: HashMap<StateId, u8> = HashMap::new();
    let dense: Vec<u8> = seq
        .iter()
        .map(|s| {
            let n = ids.len() as u8;
            *ids.entry(*s).or_insert(n)
        })
        .collect();
    let mut e = Exact {
        seq: &dense,
        k: k.min(seq.len().max(1)),
        memo: HashMap::new(),
    };
    let mut buf = vec![0u8; ids.len()];
    Ok(u64::from(e.best(0, &mut buf, NONE)))
}
