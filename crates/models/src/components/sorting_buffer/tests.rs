//! Unit tests of the sorting buffer.

use super::sequence::{lru_worst, parse_sequence};
use super::*;

fn changes(seq: &[StateId], k: usize, s: Strategy) -> u64 {
    simulate(seq, k, s, 1, false).unwrap().state_changes
}

#[test]
fn one_slot_reorders_nothing() {
    let seq = [1, 1, 2, 1, 3, 3, 2];
    for s in Strategy::ALL {
        assert_eq!(changes(&seq, 1, s), input_runs(&seq), "{s:?}");
    }
    assert_eq!(input_runs(&seq), 5);
}

#[test]
fn a_buffer_as_large_as_the_sequence_groups_everything() {
    let seq = [1, 2, 3, 1, 2, 3, 1, 2, 3];
    for s in Strategy::ALL {
        assert_eq!(changes(&seq, seq.len() + 1, s), 3, "{s:?}");
    }
}

#[test]
fn lru_sends_the_oldest_state() {
    // K = 3: [1 2 3] full -> LRU sends 1; [2 3 2] full (stamp 2 newest) -> sends 3;
    // [2 2 1]...
    let r = simulate(&[1, 2, 3, 2, 1], 3, Strategy::Lru, 0, true).unwrap();
    assert_eq!(r.output.unwrap(), vec![(1, 1), (3, 1), (2, 2), (1, 1)]);
}

#[test]
fn output_is_a_permutation_of_the_input() {
    let seq: Vec<StateId> = (0..200u64).map(|i| (i * 7919) % 13).collect();
    for s in Strategy::ALL {
        for k in [1, 2, 5, 16] {
            let r = simulate(&seq, k, s, 3, true).unwrap();
            let out = r.output.unwrap();
            let mut counts = std::collections::HashMap::new();
            for (c, n) in &out {
                *counts.entry(*c).or_insert(0u64) += n;
            }
            for c in &seq {
                *counts.get_mut(c).unwrap() -= 1;
            }
            assert!(counts.values().all(|&v| v == 0));
            assert_eq!(out.len() as u64, r.state_changes);
            assert!(out.windows(2).all(|w| w[0].0 != w[1].0));
        }
    }
}

#[test]
fn random_is_reproducible_per_seed() {
    let seq: Vec<StateId> = (0..500u64).map(|i| (i * i + 3 * i) % 17).collect();
    let a = simulate(&seq, 8, Strategy::Random, 5, true).unwrap();
    let b = simulate(&seq, 8, Strategy::Random, 5, true).unwrap();
    assert_eq!(a, b);
    let others: Vec<_> = (6..12)
        .map(|s| simulate(&seq, 8, Strategy::Random, s, true).unwrap())
        .collect();
    assert!(others.iter().any(|o| o.output != a.output));
}

#[test]
fn buffer_sizes_are_checked() {
    assert_eq!(
        simulate(&[1], 0, Strategy::Lru, 0, false),
        Err(SortBufferError::ZeroBuffer)
    );
    assert!(matches!(
        simulate(&[1], MAX_BUFFER + 1, Strategy::Lru, 0, false),
        Err(SortBufferError::BufferTooLarge { .. })
    ));
}

#[test]
fn lower_bound_examples() {
    // a b a b, K = 1: D = 2, S max = 2 (after the second element) -> 3.
    assert_eq!(lower_bound(&[1, 2, 1, 2], 1), 3);
    assert_eq!(lower_bound(&[1, 2, 1, 2], 2), 2);
    assert_eq!(offline_optimum(&[1, 2, 1, 2], 1).unwrap(), 4);
    // K = 2: 1 is sent on the first overflow, the second 1 joins its run.
    assert_eq!(offline_optimum(&[1, 2, 1, 2], 2).unwrap(), 2);
    assert_eq!(offline_optimum(&[1, 2, 1, 2], 3).unwrap(), 2);
}

#[test]
fn lru_worst_case_costs_m_times_m_plus_1() {
    for m in [2u64, 3, 4, 6, 8] {
        let seq = lru_worst(m).unwrap();
        let k = (m * m + 1) as usize;
        assert_eq!(lower_bound(&seq, k), 2 * m, "m={m}");
        assert_eq!(changes(&seq, k, Strategy::Lru), m * (m + 1), "m={m}");
    }
}

#[test]
fn parsing() {
    assert_eq!(
        parse_sequence("1 2\n3\t4 # five\n\n 6", "f").unwrap(),
        vec![1, 2, 3, 4, 6]
    );
    let e = parse_sequence("1 2\n3 x4 5\n", "seq.txt").unwrap_err();
    assert_eq!(
        e.to_string(),
        "seq.txt:2:3: \"x4\" is not a state id (a non-negative integer)"
    );
    let e = parse_sequence("1 -2", "f").unwrap_err();
    assert!(e.to_string().contains("f:1:3"), "{e}");
    assert!(matches!(
        parse_sequence("# nothing\n\n", "f"),
        Err(SortBufferError::Empty { .. })
    ));
}

/// Bounded waste in its direct form (every buffered state's counter grown
/// on each overflow, the largest chosen, ties by more elements, then the
/// older stamp), written apart from the library's grouped counters: the
/// runs it sends.
fn bounded_waste_direct(seq: &[StateId], k: usize) -> Vec<(StateId, u64)> {
    let mut count: HashMap<StateId, u64> = HashMap::new();
    let mut stamp: HashMap<StateId, u64> = HashMap::new();
    let mut waste: HashMap<StateId, u64> = HashMap::new();
    let mut out: Vec<(StateId, u64)> = Vec::new();
    let send = |c: StateId, n: u64, out: &mut Vec<(StateId, u64)>| match out.last_mut() {
        Some(l) if l.0 == c => l.1 += n,
        _ => out.push((c, n)),
    };
    let mut filled = 0;
    for (t, &c) in seq.iter().enumerate() {
        *count.entry(c).or_insert(0) += 1;
        stamp.insert(c, t as u64);
        filled += 1;
        if filled < k {
            continue;
        }
        for (s, n) in &count {
            *waste.entry(*s).or_insert(0) += n;
        }
        let best = *count
            .keys()
            .max_by_key(|s| (waste[*s], count[*s], std::cmp::Reverse(stamp[*s])))
            .unwrap();
        waste.insert(best, 0);
        let n = count.remove(&best).unwrap();
        filled -= n as usize;
        send(best, n, &mut out);
    }
    if let Some(&(l, _)) = out.last()
        && let Some(n) = count.remove(&l)
    {
        send(l, n, &mut out);
    }
    let mut rest: Vec<(u64, StateId, u64)> = count.iter().map(|(s, n)| (stamp[s], *s, *n)).collect();
    rest.sort();
    for (_, s, n) in rest {
        send(s, n, &mut out);
    }
    out
}

#[test]
fn bounded_waste_chooses_as_its_direct_form() {
    // Sequences with few and many states, skewed and flat, through buffers
    // from 1 slot to more than the sequence: the same runs sent.
    let mut x = 12345u64;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for case in 0..300 {
        let len = 1 + (next() % 400) as usize;
        let states = 1 + next() % [3, 10, 60, 400][case % 4];
        let seq: Vec<StateId> = (0..len)
            .map(|_| {
                let r = next();
                // Skewed: low ids more often.
                if case % 3 == 0 {
                    (r % states) * (r % states) % states
                } else {
                    r % states
                }
            })
            .collect();
        for k in [1, 2, 3, 5, 8, 17, 64, 500] {
            let r = simulate(&seq, k, Strategy::BoundedWaste, 1, true).unwrap();
            assert_eq!(
                r.output.unwrap(),
                bounded_waste_direct(&seq, k),
                "case {case}, k = {k}, {seq:?}"
            );
        }
    }
}

#[test]
fn random_sequences_are_reproducible_and_follow_their_law() {
    use super::sequence::{random_states, sequence_from_spec};
    let a = random_states(50_000, 8, 0.0, 7).unwrap();
    assert_eq!(a, random_states(50_000, 8, 0.0, 7).unwrap(), "same seed, same ids");
    assert_ne!(a, random_states(50_000, 8, 0.0, 8).unwrap(), "another seed, other ids");
    // Uniform: every state about 1/8 of the ids (6,250 each; 5 sigma is about 370).
    let mut counts = [0u64; 8];
    a.iter().for_each(|&s| counts[s as usize] += 1);
    assert!(counts.iter().all(|&c| c.abs_diff(6_250) < 370), "{counts:?}");
    // Zipf with exponent 1 over 4 states: weights 1, 1/2, 1/3, 1/4 (sum 25/12).
    let z = random_states(60_000, 4, 1.0, 1).unwrap();
    let mut zc = [0u64; 4];
    z.iter().for_each(|&s| zc[s as usize] += 1);
    for (i, &c) in zc.iter().enumerate() {
        let want = 60_000.0 * (1.0 / (i + 1) as f64) / (25.0 / 12.0);
        assert!((c as f64 - want).abs() < 5.0 * want.sqrt(), "state {i}: {c} vs {want}");
    }
    // The spec form, and its errors.
    let base = std::path::Path::new(".");
    assert_eq!(sequence_from_spec("random:50000:8:0:7", base).unwrap(), a);
    for (bad, want) in [
        ("random:10:4:0", "expected random:N:D:S:SEED"),
        ("random:x:4:0:1", "expected random:N:D:S:SEED"),
        ("random:0:4:0:1", "must be between 1 and"),
        ("random:10:0:0:1", "must be between 1 and"),
        ("random:10:4:-1:1", "Zipf exponent S must be a number from 0 to 10"),
        ("random:10:4:nan:1", "Zipf exponent S must be a number from 0 to 10"),
    ] {
        let e = sequence_from_spec(bad, base).unwrap_err().to_string();
        assert!(e.contains(want), "{bad}: {e}");
    }
}
