//! Tests for [`super::Mesh`].

use super::*;

/// Paper 000, Figure 1: strip `1 2 3 4 5 6 - 1 3 5`.
fn figure1() -> Mesh {
    Mesh {
        name: "figure1".into(),
        topology: Topology::TriangleStrip,
        indices: vec![1, 2, 3, 4, 5, 6, RESTART, 1, 3, 5],
        vertex_count: 7,
    }
}

#[test]
fn figure1_oracle() {
    let m = figure1();
    m.validate().unwrap();
    assert_eq!(m.triangles(), 5);
    assert_eq!(m.index_count(), 9);
    assert_eq!(m.vertices(), 15);
    assert_eq!(m.unique_vertices(), 6);
    for p in [CachePolicy::Fifo(16), CachePolicy::Lru(16)] {
        let s = m.cache_stats(&p);
        assert_eq!(
            s,
            CacheStats {
                indices: 9,
                triangles: 5,
                unique_vertices: 6,
                transformed: 6
            },
            "{p}"
        );
        assert_eq!(m.misses_per_triangle(&p), [3, 1, 1, 1, 0]);
    }
    // Without a cache every index is transformed.
    assert_eq!(m.cache_stats(&CachePolicy::None).transformed, 9);
    assert_eq!(m.misses_per_triangle(&CachePolicy::None), [3, 1, 1, 1, 3]);
}

#[test]
fn restart_does_not_flush_but_small_cache_evicts() {
    // fifo:4 over 1 2 3 4 5 6 | 1 3 5: at the restart the FIFO holds
    // 3 4 5 6; 1 misses (-> 4 5 6 1), 3 misses (-> 5 6 1 3), 5 hits.
    let s = figure1().cache_stats(&CachePolicy::Fifo(4));
    assert_eq!(s.transformed, 8);
}

#[test]
fn short_runs_are_not_fetched() {
    let m = Mesh {
        name: "short".into(),
        topology: Topology::TriangleStrip,
        indices: vec![RESTART, 0, 1, RESTART, 2, 3, 4, RESTART, RESTART, 5, RESTART],
        vertex_count: 6,
    };
    m.validate().unwrap();
    assert_eq!(m.triangles(), 1);
    assert_eq!(m.index_count(), 3);
    assert_eq!(m.unique_vertices(), 3);
    let s = m.cache_stats(&CachePolicy::Fifo(8));
    assert_eq!((s.indices, s.transformed), (3, 3));
    assert_eq!(m.misses_per_triangle(&CachePolicy::Fifo(8)), [3]);
}

#[test]
fn list_counts_and_misses() {
    let m = Mesh {
        name: "quad".into(),
        topology: Topology::TriangleList,
        indices: vec![0, 1, 2, 2, 1, 3],
        vertex_count: 4,
    };
    m.validate().unwrap();
    assert_eq!((m.triangles(), m.index_count(), m.vertices()), (2, 6, 6));
    assert_eq!(m.misses_per_triangle(&CachePolicy::Fifo(4)), [3, 1]);
    let s = m.cache_stats(&CachePolicy::Lru(2));
    // lru:2: 0 1 2 miss, 2 hit, 1 hit, 3 miss.
    assert_eq!(s.transformed, 4);
    assert_eq!(m.cache_stats(&CachePolicy::Fifo(1)).transformed, 5);
    assert!((s.acmr() - 2.0).abs() < 1e-12);
}

#[test]
fn validation_errors() {
    let mut m = figure1();
    m.vertex_count = 6;
    assert!(matches!(
        m.validate(),
        Err(MeshError::IndexOutOfRange {
            position: 5,
            index: 6,
            ..
        })
    ));
    let list = Mesh {
        name: "l".into(),
        topology: Topology::TriangleList,
        indices: vec![0, 1, RESTART],
        vertex_count: 3,
    };
    assert!(matches!(list.validate(), Err(MeshError::RestartInList(2))));
    let list = Mesh {
        indices: vec![0, 1],
        ..list
    };
    let e = list.validate().unwrap_err();
    assert!(e.to_string().contains("not a multiple of 3"), "{e}");
}

#[test]
fn strip_to_list_alternates_winding() {
    let l = figure1().to_triangle_list();
    assert_eq!(l.topology, Topology::TriangleList);
    assert_eq!(l.indices, [1, 2, 3, 3, 2, 4, 3, 4, 5, 5, 4, 6, 1, 3, 5]);
    l.validate().unwrap();
    assert_eq!(l.triangles(), 5);
    assert_eq!(l.unique_vertices(), 6);
    assert_eq!(l.cache_stats(&CachePolicy::Fifo(16)).transformed, 6);
    let again = l.to_triangle_list();
    assert_eq!(again, l);
}

mod props {
    use super::*;
    use proptest::prelude::*;

    fn strip_indices() -> impl Strategy<Value = Vec<u32>> {
        prop::collection::vec(prop_oneof![9 => 0u32..12, 1 => Just(RESTART)], 0..80)
    }

    fn policies() -> impl Strategy<Value = CachePolicy> {
        prop_oneof![
            Just(CachePolicy::None),
            (1u32..10).prop_map(CachePolicy::Fifo),
            (1u32..10).prop_map(CachePolicy::Lru),
        ]
    }

    proptest! {
        #[test]
        fn strip_miss_accounting(indices in strip_indices(), p in policies()) {
            let m = Mesh { name: "p".into(), topology: Topology::TriangleStrip, indices, vertex_count: 12 };
            m.validate().unwrap();
            let per = m.misses_per_triangle(&p);
            let s = m.cache_stats(&p);
            prop_assert_eq!(per.len() as u64, m.triangles());
            prop_assert_eq!(s.triangles, m.triangles());
            prop_assert_eq!(s.indices, m.index_count());
            prop_assert_eq!(per.iter().map(|&x| u64::from(x)).sum::<u64>(), s.transformed);
            prop_assert!(s.transformed <= s.indices);
            prop_assert!(s.transformed >= s.unique_vertices);
            let l = m.to_triangle_list();
            prop_assert_eq!(l.triangles(), m.triangles());
            prop_assert_eq!(l.unique_vertices(), m.unique_vertices());
        }
    }
}
