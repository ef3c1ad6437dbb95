//! The exact multiple-choice knapsack by branch and bound, so that the
//! greedy's gap can be shown (paper 001 calls the problem NP-complete and
//! solves it greedily; this is the reference the greedy is measured
//! against).
//!
//! Depth-first over objects (most valuable first), each object's levels
//! tried by benefit, highest first, then "not drawn". A branch is cut when
//! its benefit so far plus an upper bound on what the remaining objects can
//! add is no better than the best selection found. The bound is the linear
//! relaxation of the remaining multiple-choice knapsack (Sinha & Zoltners
//! 1979): each object's levels reduced to the upper concave hull of its
//! (cost, benefit) points with (0, 0), the hull segments of all remaining
//! objects filled by slope, highest first, the last one fractionally. The
//! search starts from the greedy selection, so the result is never worse
//! than the greedy's. Benefits are `f64`: the optimum is exact up to a
//! relative rounding of 1e-12.
//!
//! Limited to [`MAX_OPTIMAL_OBJECTS`] objects; a search that visits more
//! than [`MAX_OPTIMAL_NODES`] nodes gives up with an error instead of
//! running for hours.

use super::{Instance, LodSelectError, Selection, greedy};

/// Most objects [`optimal`] accepts.
pub const MAX_OPTIMAL_OBJECTS: usize = 30;

/// Most branch-and-bound nodes [`optimal`] visits before it gives up.
pub const MAX_OPTIMAL_NODES: u64 = 20_000_000;

const REL_TOL: f64 = 1e-12;

/// One object's candidate levels and hull.
struct Item {
    /// Original object index.
    object: usize,
    /// (level, cost, benefit), benefit descending.
    levels: Vec<(u32, u64, f64)>,
}

struct Search<'a> {
    items: &'a [Item],
    /// Per suffix i: hull segments (cost, benefit) of items i.., slope descending.
    suffix: Vec<Vec<(u64, f64)>>,
    current: Vec<Option<u32>>,
    best: f64,
    best_levels: Vec<Option<u32>>,
    nodes: u64,
    gave_up: bool,
}

/// The upper concave hull of an item's levels with (0, 0), as segments
/// (cost step, benefit step) of decreasing slope.
fn hull_segments(levels: &[(u32, u64, f64)]) -> Vec<(u64, f64)> {
    let mut pts: Vec<(u64, f64)> = levels.iter().map(|&(_, c, b)| (c, b)).collect();
    pts.push((0, 0.0));
    // By cost, and at equal cost the best benefit only.
    pts.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
    pts.dedup_by(|a, b| a.0 == b.0);
    // Points must rise in benefit; the hull from the cheapest point.
    let mut hull: Vec<(u64, f64)> = Vec::new();
    for p in pts {
        if let Some(&last) = hull.last()
            && p.1 <= last.1
        {
            continue;
        }
        while hull.len() >= 2 {
            let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            // Drop b when it lies on or below the chord a -> p.
            let lhs = (b.1 - a.1) * (p.0 - a.0) as f64;
            let rhs = (p.1 - a.1) * (b.0 - a.0) as f64;
            if lhs <= rhs {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(p);
    }
    // The first point is (0, b0) with b0 >= 0: a zero-cost level; its
    // benefit is a segment of zero cost.
    let mut segs = Vec::new();
    let mut prev = (0u64, 0.0);
    for p in hull {
        if p.1 > prev.1 {
            segs.push((p.0 - prev.0, p.1 - prev.1));
        }
        prev = p;
    }
    segs
}

fn slope_desc(a: &(u64, f64), b: &(u64, f64)) -> std::cmp::Ordering {
    // a.1/a.0 vs b.1/b.0, zero cost = infinite slope.
    let sa = if a.0 == 0 { f64::INFINITY } else { a.1 / a.0 as f64 };
    let sb = if b.0 == 0 { f64::INFINITY } else { b.1 / b.0 as f64 };
    sb.total_cmp(&sa)
}

impl Search<'_> {
    fn bound(&self, i: usize, mut cap: u64) -> f64 {
        let mut v = 0.0;
        for &(c, b) in &self.suffix[i] {
            if c <= cap {
                cap -= c;
                v += b;
            } else {
                v += b * cap as f64 / c as f64;
                break;
            }
        }
        v
    }

    fn dfs(&mut self, i: usize, cap: u64, value: f64) {
        if self.gave_up {
            return;
        }
        self.nodes += 1;
        if self.nodes > MAX_OPTIMAL_NODES {
            self.gave_up = true;
            return;
        }
        if i == self.items.len() {
            if value > self.best + REL_TOL * self.best.abs() {
                self.best = value;
                for (it, l) in self.items.iter().zip(&self.current) {
                    self.best_levels[it.object] = *l;
                }
            }
            return;
        }
        if value + self.bound(i, cap) <= self.best + REL_TOL * self.best.abs() {
            return;
        }
        let items = self.items;
        for &(l, c, b) in &items[i].levels {
            if c <= cap {
                self.current[i] = Some(l);
                self.dfs(i + 1, cap - c, value + b);
            }
        }
        self.current[i] = None;
        self.dfs(i + 1, cap, value);
    }
}

/// An optimal selection of `inst` (at most [`MAX_OPTIMAL_OBJECTS`] objects).
pub fn optimal(inst: &Instance) -> Result<Selection, LodSelectError> {
    let objects = inst.objects();
    if objects.len() > MAX_OPTIMAL_OBJECTS {
        return Err(LodSelectError::TooLargeForOptimal {
            objects: objects.len(),
            limit: MAX_OPTIMAL_OBJECTS,
        });
    }
    let budget = inst.budget().0;
    let mut items: Vec<Item> = objects
        .iter()
        .enumerate()
        .map(|(object, o)| {
            let mut levels: Vec<(u32, u64, f64)> = o
                .levels
                .iter()
                .enumerate()
                .filter(|(_, l)| l.benefit > 0.0 && l.cost.0 <= budget)
                .map(|(i, l)| (i as u32, l.cost.0, l.benefit))
                .collect();
            levels.sort_by(|a, b| b.2.total_cmp(&a.2).then(a.1.cmp(&b.1)).then(a.0.cmp(&b.0)));
            // A level that costs no less than a better one is dominated.
            let mut kept: Vec<(u32, u64, f64)> = Vec::new();
            for lv in levels {
                if kept.iter().all(|k| lv.1 < k.1) {
                    kept.push(lv);
                }
            }
            Item { object, levels: kept }
        })
        .filter(|it| !it.levels.is_empty())
        .collect();
    // Most valuable objects first: the bound tightens fastest.
    items.sort_by(|a, b| b.levels[0].2.total_cmp(&a.levels[0].2).then(a.object.cmp(&b.object)));
    let mut suffix: Vec<Vec<(u64, f64)>> = vec![Vec::new(); items.len() + 1];
    for i in (0..items.len()).rev() {
        let mut s = suffix[i + 1].clone();
        s.extend(hull_segments(&items[i].levels));
        s.sort_by(slope_desc);
        suffix[i] = s;
    }
    let start = greedy(inst);
    let mut search = Search {
        items: &items,
        suffix,
        current: vec![None; items.len()],
        best: start.total_benefit,
        best_levels: start.levels.clone(),
        nodes: 0,
        gave_up: false,
    };
    search.dfs(0, budget, 0.0);
    if search.gave_up {
        return Err(LodSelectError::SearchLimit {
            nodes: search.nodes,
            best: search.best,
        });
    }
    if search.best_levels == start.levels {
        return Ok(start);
    }
    Ok(Selection::evaluate(inst, search.best_levels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_drops_points_below_chords() {
        // (1,1) (2,1.5) (3,3): (2,1.5) lies below the chord (1,1)-(3,3).
        let s = hull_segments(&[(0, 1, 1.0), (1, 2, 1.5), (2, 3, 3.0)]);
        assert_eq!(s, vec![(3, 3.0)]);
        let s = hull_segments(&[(0, 1, 2.0), (1, 3, 3.0)]);
        assert_eq!(s, vec![(1, 2.0), (2, 1.0)]);
        // A zero-cost level is a zero-cost segment.
        let s = hull_segments(&[(0, 0, 1.0), (1, 2, 3.0)]);
        assert_eq!(s, vec![(0, 1.0), (2, 2.0)]);
    }
}
