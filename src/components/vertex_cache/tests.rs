//! Tests for [`super::VertexCache`] and [`super::CachePolicy`].

use super::*;
use proptest::prelude::*;
use std::collections::VecDeque;

fn misses(policy: &CachePolicy, seq: &[u32]) -> Vec<bool> {
    let mut c = VertexCache::new(policy, 4);
    seq.iter().map(|&i| c.access(i)).collect()
}

/// Naive FIFO: a queue of at most n entries, hits do not reorder.
fn fifo_ref(n: usize, seq: &[u32]) -> Vec<bool> {
    let mut q = VecDeque::new();
    seq.iter()
        .map(|&i| {
            if q.contains(&i) {
                false
            } else {
                if q.len() == n {
                    q.pop_front();
                }
                q.push_back(i);
                true
            }
        })
        .collect()
}

/// Naive LRU: a list, most recent at the back.
fn lru_ref(n: usize, seq: &[u32]) -> Vec<bool> {
    let mut q: Vec<u32> = Vec::new();
    seq.iter()
        .map(|&i| {
            if let Some(p) = q.iter().position(|&v| v == i) {
                q.remove(p);
                q.push(i);
                false
            } else {
                if q.len() == n {
                    q.remove(0);
                }
                q.push(i);
                true
            }
        })
        .collect()
}

#[test]
fn fifo_hand_worked() {
    // fifo:2. 0 miss [0]; 1 miss [0 1]; 0 hit (no reorder); 2 miss evicts 0
    // -> [1 2]; 0 miss evicts 1 -> [2 0]; 1 miss -> [0 1]; 0 hit.
    let seq = [0, 1, 0, 2, 0, 1, 0];
    assert_eq!(
        misses(&CachePolicy::Fifo(2), &seq),
        [true, true, false, true, true, true, false]
    );
}

#[test]
fn lru_hand_worked() {
    // lru:2. 0 miss [0]; 1 miss [1 0]; 0 hit -> [0 1]; 2 miss evicts 1
    // -> [2 0]; 0 hit -> [0 2]; 1 miss evicts 2 -> [1 0]; 0 hit.
    let seq = [0, 1, 0, 2, 0, 1, 0];
    assert_eq!(
        misses(&CachePolicy::Lru(2), &seq),
        [true, true, false, true, false, true, false]
    );
}

#[test]
fn none_always_misses_and_reset_empties() {
    assert!(misses(&CachePolicy::None, &[1, 1, 1]).iter().all(|m| *m));
    for p in [CachePolicy::Fifo(4), CachePolicy::Lru(4)] {
        let mut c = VertexCache::new(&p, 0);
        assert!(c.access(3));
        assert!(!c.access(3));
        c.reset();
        assert!(c.access(3), "{p}");
        assert!(!c.access(3));
    }
}

#[test]
fn fifo_grows_and_handles_huge_ids() {
    let mut c = VertexCache::new(&CachePolicy::Fifo(3), 0);
    for i in [5, 1000, u32::MAX - 1, 7] {
        assert!(c.access(i));
    }
    // 5 was evicted by the fourth insertion; the others remain.
    assert!(c.access(5));
    assert!(!c.access(u32::MAX - 1));
    assert!(!c.access(7));
}

#[test]
fn policy_strings_round_trip() {
    for s in ["none", "fifo:24", "lru:16", "fifo:1"] {
        let p: CachePolicy = s.parse().unwrap();
        assert_eq!(p.to_string(), s);
    }
    assert_eq!("FIFO:8".parse::<CachePolicy>(), Ok(CachePolicy::Fifo(8)));
}

#[test]
fn policy_string_errors() {
    let e = |s: &str| s.parse::<CachePolicy>().unwrap_err().to_string();
    assert!(e("fifo").contains("needs a size"), "{}", e("fifo"));
    assert!(e("fifo:0").contains("`0`"), "{}", e("fifo:0"));
    assert!(e("fifo:x").contains("`x`"), "{}", e("fifo:x"));
    assert!(e("fifo:-3").contains("`-3`"));
    assert!(e("lfu:3").contains("unknown") && e("lfu:3").contains("lru:N"));
    assert!(e("none:3").contains("`none` takes no size"), "{}", e("none:3"));
    // The error names the policy given, not another one.
    assert!(
        e("lavapipe:3").contains("`lavapipe` takes no size"),
        "{}",
        e("lavapipe:3")
    );
    assert!(!e("lavapipe:3").contains("`none`"), "{}", e("lavapipe:3"));
    assert!(e("").contains("unknown"));
}

#[test]
fn policy_serde_as_string() {
    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct H {
        cache: CachePolicy,
    }
    let h: H = toml::from_str("cache = \"lru:16\"").unwrap();
    assert_eq!(h.cache, CachePolicy::Lru(16));
    assert_eq!(toml::to_string(&h).unwrap().trim(), "cache = \"lru:16\"");
    let err = toml::from_str::<H>("cache = \"fifo:0\"").unwrap_err();
    assert!(err.to_string().contains("fifo:0"));
}

#[test]
fn stats_ratios() {
    let s = CacheStats {
        indices: 9,
        triangles: 5,
        unique_vertices: 6,
        transformed: 6,
    };
    assert_eq!(s.acmr(), 1.2);
    assert_eq!(s.atvr(), 1.0);
    assert_eq!(CacheStats::default().acmr(), 0.0);
    assert_eq!(CacheStats::default().atvr(), 0.0);
}

proptest! {
    #[test]
    fn fifo_matches_naive(n in 1usize..12, seq in prop::collection::vec(0u32..40, 0..300)) {
        prop_assert_eq!(misses(&CachePolicy::Fifo(n as u32), &seq), fifo_ref(n, &seq));
    }

    #[test]
    fn lru_matches_naive(n in 1usize..12, seq in prop::collection::vec(0u32..40, 0..300)) {
        prop_assert_eq!(misses(&CachePolicy::Lru(n as u32), &seq), lru_ref(n, &seq));
    }

    #[test]
    fn fifo_reset_matches_fresh(n in 1u32..8, a in prop::collection::vec(0u32..20, 0..50),
                                b in prop::collection::vec(0u32..20, 0..50)) {
        let p = CachePolicy::Fifo(n);
        let mut c = VertexCache::new(&p, 0);
        for &i in &a { c.access(i); }
        c.reset();
        let after: Vec<bool> = b.iter().map(|&i| c.access(i)).collect();
        prop_assert_eq!(after, fifo_ref(n as usize, &b));
    }
}
