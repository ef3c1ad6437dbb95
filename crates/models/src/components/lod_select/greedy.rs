//! The lecture's greedy selection (paper 001, slide "Optimierungsproblem:
//! multiple-choice knapsack problem"): value(O, L) = benefit / cost; sort all
//! object tuples by value, highest first; take a tuple when its object has
//! none yet and it fits in what is left of the budget.
//!
//! Order among tuples: value descending (a zero-cost tuple with positive
//! benefit has value +infinity); equal values: higher benefit first, then
//! lower object index, then lower level index, so the result is
//! deterministic. Zero-benefit tuples are left out (see the module above),
//! as are tuples that cost more than the whole budget (they can never fit).

use super::{Instance, Selection};

/// The greedy selection of `inst`. O(T log T) for T tuples.
pub fn greedy(inst: &Instance) -> Selection {
    let budget = inst.budget().0;
    let objects = inst.objects();
    // (value, benefit, object, level, cost)
    let mut tuples: Vec<(f64, f64, u32, u32, u64)> = Vec::with_capacity(inst.tuples());
    for (o, obj) in objects.iter().enumerate() {
        for (l, lv) in obj.levels.iter().enumerate() {
            if lv.benefit > 0.0 && lv.cost.0 <= budget {
                let value = if lv.cost.0 == 0 {
                    f64::INFINITY
                } else {
                    lv.benefit / lv.cost.0 as f64
                };
                tuples.push((value, lv.benefit, o as u32, l as u32, lv.cost.0));
            }
        }
    }
    tuples.sort_unstable_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then(b.1.total_cmp(&a.1))
            .then(a.2.cmp(&b.2))
            .then(a.3.cmp(&b.3))
    });
    let mut left = budget;
    let mut chosen: Vec<Option<u32>> = vec![None; objects.len()];
    let mut open = objects.len();
    for (_, _, o, l, c) in tuples {
        if open == 0 {
            break;
        }
        let slot = &mut chosen[o as usize];
        if slot.is_none() && c <= left {
            *slot = Some(l);
            left -= c;
            open -= 1;
        }
    }
    Selection::evaluate(inst, chosen)
}
