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
fn lookback_and_nvidia_strings() {
    for s in ["lookback:32,32,42", "lookback:3,1,1", "nvidia"] {
        let p: CachePolicy = s.parse().unwrap();
        assert_eq!(p.to_string(), s);
    }
    assert_eq!(
        " Lookback: 32, 32 ,42 ".parse::<CachePolicy>(),
        Ok(CachePolicy::Lookback {
            vertices: 32,
            triangles: 32,
            window: 42
        })
    );
    assert_eq!("NVIDIA".parse::<CachePolicy>(), Ok(CachePolicy::Nvidia));
    let e = |s: &str| s.parse::<CachePolicy>().unwrap_err().to_string();
    assert!(e("nvidia:3").contains("`nvidia` takes no size"), "{}", e("nvidia:3"));
    assert!(e("lookback").contains("needs a size"), "{}", e("lookback"));
    assert!(e("lookback:32,32").contains("lookback:VERTICES,TRIANGLES,WINDOW"));
    assert!(e("lookback:32,32,42,1").contains("lookback:VERTICES,TRIANGLES,WINDOW"));
    assert!(e("lookback:2,32,42").contains("VERTICES must be at least 3"));
    assert!(e("lookback:32,0,42").contains("at least 1"));
    assert!(e("lookback:32,32,0").contains("at least 1"));
    assert!(e("lookback:32,x,42").contains("`x`"), "{}", e("lookback:32,x,42"));
    assert!(e("lfu:3").contains("`nvidia`"), "{}", e("lfu:3"));
}

/// Misses per triangle and batches under `policy`.
fn per_triangle(policy: &CachePolicy, tris: &[[u32; 3]]) -> (Vec<u8>, u64) {
    let mut c = VertexCache::new(policy, 0);
    let m = tris.iter().map(|&t| c.access_triangle(t)).collect();
    (m, c.warps())
}

#[test]
fn lookback_hand_worked() {
    // lookback:6,4,4. T0 (positions 0-2): 3 misses, 3 vertices shaded.
    // T1 (3-5): 2 and 1 were read 1 and 3 indices ago, 3 is new: 1 miss.
    // T2 (6-8): 0 was read 6 indices ago, beyond the window of 4, so it is
    // shaded again although the batch holds it; 3 hits; 4 new: 2 misses,
    // 6 vertices. T3 (9-11): 4 and 3 hit but 5 does not fit (7 > 6): a new
    // batch begins and all three are shaded.
    let p: CachePolicy = "lookback:6,4,4".parse().unwrap();
    let tris = [[0, 1, 2], [2, 1, 3], [0, 3, 4], [4, 3, 5]];
    assert_eq!(per_triangle(&p, &tris), (vec![3, 1, 2, 3], 2));
    // With a window as long as the batch, 0 is reused in T2 and T3 fits.
    let whole: CachePolicy = "lookback:6,4,12".parse().unwrap();
    assert_eq!(per_triangle(&whole, &tris), (vec![3, 1, 1, 1], 1));
    // The triangle limit: a fifth triangle starts a new batch.
    let mut five = tris.to_vec();
    five.push([5, 4, 3]);
    assert_eq!(per_triangle(&whole, &five), (vec![3, 1, 1, 1, 3], 2));
}

#[test]
fn lookback_repeats_inside_a_triangle_are_shaded_once() {
    let p: CachePolicy = "lookback:3,32,1".parse().unwrap();
    // 0 0 1: two vertices; 1 1 1: one (1 was read 1 index ago); 2 0 2: 0 is
    // beyond the window, 2 is repeated inside the triangle.
    assert_eq!(per_triangle(&p, &[[0, 0, 1], [1, 1, 1], [2, 0, 2]]), (vec![2, 0, 2], 2));
}

#[test]
fn lookback_reset_and_single_indices() {
    let p = CachePolicy::Nvidia;
    let mut c = VertexCache::new(&p, 0);
    assert!(c.is_triangle_level());
    assert_eq!(c.access_triangle([0, 1, 2]), 3);
    assert_eq!(c.access_triangle([2, 1, 0]), 0);
    c.reset();
    assert_eq!(c.access_triangle([2, 1, 0]), 3);
    assert_eq!(c.warps(), 2);
    // Single indices: a window of 42 indices, no batch limits; huge ids too.
    let mut c = VertexCache::new(&p, 0);
    assert!(c.access(u32::MAX - 1));
    for i in 0..41 {
        assert!(c.access(i));
    }
    assert!(!c.access(u32::MAX - 1), "read 42 indices ago");
    for i in 100..142 {
        assert!(c.access(i));
    }
    assert!(c.access(u32::MAX - 1), "read 43 indices ago");
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

    /// With a window covering a whole batch (3 indices per triangle), and
    /// no vertex repeated inside a triangle, `lookback:V,T,3T` is `batch:V,T`.
    #[test]
    fn long_lookback_is_batch(v in 3u32..40, t in 1u32..40,
                              raw in prop::collection::vec((0u32..60, 1u32..60, 1u32..60), 0..200)) {
        let tris: Vec<[u32; 3]> = raw.iter().map(|&(a, b, c)| [a, a + b, a + b + c]).collect();
        let lookback = CachePolicy::Lookback { vertices: v, triangles: t, window: 3 * t };
        let batch = CachePolicy::Batch { vertices: v, triangles: t };
        prop_assert_eq!(per_triangle(&lookback, &tris), per_triangle(&batch, &tris));
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

    /// `direct:SLOTS,SEGMENT` against its plain form (every slot emptied at
    /// each segment's start and at a reset), with resets between runs of
    /// triangles and ids up to the empty marker.
    #[test]
    fn direct_matches_naive(slots in 1u32..20, segment in 1u32..12,
                            runs in prop::collection::vec(
                                prop::collection::vec((0u32..50, 0u32..50, 0u32..50), 0..60), 1..4),
                            huge in any::<bool>()) {
        let p = CachePolicy::Direct { slots, segment };
        let mut c = VertexCache::new(&p, 0);
        for run in &runs {
            c.reset();
            let mut table = vec![u32::MAX; slots as usize];
            let mut prim = 0u32;
            for &(a, b, d) in run {
                let t = if huge { [a, u32::MAX - b, d] } else { [a, b, d] };
                if prim == segment {
                    table.iter_mut().for_each(|s| *s = u32::MAX);
                    prim = 0;
                }
                prim += 1;
                let mut want = 0u8;
                for v in t {
                    let s = &mut table[(v % slots) as usize];
                    if *s == v && v != u32::MAX {
                        continue;
                    }
                    *s = v;
                    want += 1;
                }
                prop_assert_eq!(c.access_triangle(t), want);
            }
        }
    }
}
