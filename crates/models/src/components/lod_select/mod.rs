//! Level-of-detail selection as a multiple-choice knapsack (paper 001,
//! slides "Prädiktive LOD-Selektion [Funkhouser und Sequin]" and the
//! "Optimierungsproblem: multiple-choice knapsack problem" slide after it).
//!
//! Every object `O` offers levels `L`, each an object tuple with a
//! [`Level::cost`] (rendering time) and a [`Level::benefit`] (its
//! contribution to the image). A selection draws at most one level per
//! object; its cost must stay within the frame's budget `T_b`, and the sum
//! of benefits is to be as large as possible. The problem is NP-complete;
//! the lecture solves it greedily by value = benefit / cost.
//!
//! Three algorithms, all on one validated [`Instance`]:
//! - [`greedy`]: the lecture's algorithm exactly (all tuples sorted by
//!   value, highest first; a tuple is taken when its object has none yet and
//!   it fits in what is left of the budget);
//! - [`incremental`]: the frame-to-frame variant of the slide after it
//!   ("Inkrementelle Lösung"): start from the previous frame's selection,
//!   repair it while it is over budget, then upgrade while that adds benefit
//!   within budget (the rule is spelt out in [`incremental`]'s module);
//! - [`optimal`]: exact branch and bound for instances of up to
//!   [`MAX_OPTIMAL_OBJECTS`] objects, so the greedy's gap can be shown.
//!
//! Defined results at the edges (documented for users in
//! `docs/lod-and-state-sorting.md`):
//! - a level with zero benefit is never selected by any algorithm: drawing
//!   it adds nothing, and leaving the object out costs no more;
//! - a level with zero cost and positive benefit has value +infinity and is
//!   always taken (it always fits);
//! - levels need not be ordered: a level index is an identifier, and costs
//!   and benefits need not rise with it. A dominated level (costing more and
//!   giving less than another of the same object) is never chosen by
//!   [`greedy`] or [`optimal`];
//! - an object none of whose levels fits the budget alone is never drawn
//!   (its selection is `None`); [`Instance::unaffordable`] names them;
//! - an empty instance gives an empty selection of cost 0 and benefit 0;
//! - negative, NaN or infinite benefits are errors naming the object and the
//!   level ([`LodSelectError`]); costs are [`Duration`]s, never negative.
//!
//! Costs are integer picoseconds; sums are taken in `u128`, so no instance
//! overflows. Benefits are `f64`.

pub mod file;
mod greedy;
mod incremental;
mod optimal;

use serde::Serialize;

use crate::engine::Duration;

pub use greedy::greedy;
pub use incremental::incremental;
pub use optimal::{MAX_OPTIMAL_NODES, MAX_OPTIMAL_OBJECTS, optimal};

/// One level of an object: an object tuple of the knapsack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// Rendering time of the object at this level.
    pub cost: Duration,
    /// Contribution to the image (non-negative, finite).
    pub benefit: f64,
}

/// An object and its levels (index 0 first; the order carries no meaning).
#[derive(Debug, Clone, PartialEq)]
pub struct LodObject {
    /// Name, for errors and reports.
    pub name: String,
    /// The levels it can be drawn at.
    pub levels: Vec<Level>,
}

/// A validated knapsack instance: a budget and objects with levels.
///
/// A 10 ms budget and two objects: A at 4 ms (benefit 10) or 8 ms (14), B
/// at 5 ms (5) or 2 ms (3). The greedy takes the tuples by benefit per ms
/// (A's 4 ms level, 2.5 per ms; then B's 2 ms level, 1.5 per ms): benefit 13
/// in 6 ms. The optimum spends the whole budget on A's 8 ms and B's 2 ms
/// levels: benefit 17.
///
/// ```
/// use rendersim_models::components::lod_select::{Algorithm, Instance, Level, LodObject};
/// use rendersim_engine::Duration;
///
/// let level = |ms, benefit| Level { cost: Duration::ms(ms), benefit };
/// let objects = vec![
///     LodObject { name: "A".into(), levels: vec![level(4, 10.0), level(8, 14.0)] },
///     LodObject { name: "B".into(), levels: vec![level(5, 5.0), level(2, 3.0)] },
/// ];
/// let inst = Instance::new(Duration::ms(10), objects).unwrap();
/// let greedy = inst.select(Algorithm::Greedy, None).unwrap();
/// assert_eq!(greedy.levels, [Some(0), Some(1)]);
/// assert_eq!((greedy.total_benefit, greedy.total_cost), (13.0, u128::from(Duration::ms(6).0)));
/// let best = inst.select(Algorithm::Optimal, None).unwrap();
/// assert_eq!(best.levels, [Some(1), Some(1)]);
/// assert_eq!(best.total_benefit, 17.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    budget: Duration,
    objects: Vec<LodObject>,
}

/// The algorithms of this module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Algorithm {
    /// [`greedy`].
    Greedy,
    /// [`incremental`].
    Incremental,
    /// [`optimal`].
    Optimal,
}

impl Algorithm {
    /// The name as written on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Greedy => "greedy",
            Algorithm::Incremental => "incremental",
            Algorithm::Optimal => "optimal",
        }
    }
}

/// Errors of LOD selection and of reading its instances.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LodSelectError {
    /// A benefit is negative, NaN or infinite.
    #[error("object {object:?} (objects[{index}]) level {level}: benefit {value:?} {why}")]
    Benefit {
        /// Object name.
        object: String,
        /// Object index in input order.
        index: usize,
        /// Level index.
        level: usize,
        /// The value.
        value: f64,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A cost could not be read.
    #[error("object {object:?} (objects[{index}]) level {level}: cost {reason}")]
    Cost {
        /// Object name.
        object: String,
        /// Object index in input order.
        index: usize,
        /// Level index.
        level: usize,
        /// What is wrong.
        reason: String,
    },
    /// An object without levels.
    #[error("object {object:?} (objects[{index}]) has no levels; give at least one {{ cost, benefit }}")]
    NoLevels {
        /// Object name.
        object: String,
        /// Object index.
        index: usize,
    },
    /// Two objects with one name (instance files only).
    #[error("objects[{first}] and objects[{second}] are both named {name:?}; names must be unique")]
    DuplicateName {
        /// The name.
        name: String,
        /// First index.
        first: usize,
        /// Second index.
        second: usize,
    },
    /// Too many objects or levels for the exact search.
    #[error(
        "the optimal selection is exact by branch and bound and limited to {limit} objects; this instance has {objects} (use greedy or incremental)"
    )]
    TooLargeForOptimal {
        /// Objects in the instance.
        objects: usize,
        /// The limit.
        limit: usize,
    },
    /// The exact search did not finish within its node limit.
    #[error(
        "the optimal search gave up after {nodes} branch-and-bound nodes without proving optimality (best benefit found {best})"
    )]
    SearchLimit {
        /// Nodes visited.
        nodes: u64,
        /// The best benefit found so far.
        best: f64,
    },
    /// The previous selection does not fit the instance.
    #[error("the previous selection has {got} entries, the instance {expected} objects")]
    PreviousLength {
        /// Objects in the instance.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// The previous selection names a level an object does not have.
    #[error(
        "the previous selection gives object {object:?} (objects[{index}]) level {level}, but it has {levels} level(s)"
    )]
    PreviousLevel {
        /// Object name.
        object: String,
        /// Object index.
        index: usize,
        /// Level given.
        level: u32,
        /// Levels the object has.
        levels: usize,
    },
    /// An instance file could not be read or parsed.
    #[error("{0}")]
    File(String),
    /// A value of an instance file is wrong: the file, the line (TOML) and
    /// the dotted key (`objects.2.levels.0.benefit`) of the value, and why.
    #[error("{file}{}: key `{key}`: {source}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    At {
        /// The file (`instance` for text given without one).
        file: String,
        /// 1-based line of the key, where it stands in the file.
        line: Option<usize>,
        /// Dotted key of the wrong value.
        key: String,
        /// What is wrong.
        source: Box<LodSelectError>,
    },
}

impl Instance {
    /// Validates and builds an instance: every benefit finite and
    /// non-negative, every object with at least one level, and the sum of
    /// every object's largest benefit finite (so no total or gap of a
    /// selection is infinite or NaN).
    pub fn new(budget: Duration, objects: Vec<LodObject>) -> Result<Instance, LodSelectError> {
        let mut best_sum = 0.0f64;
        for (index, o) in objects.iter().enumerate() {
            if o.levels.is_empty() {
                return Err(LodSelectError::NoLevels {
                    object: o.name.clone(),
                    index,
                });
            }
            if o.levels.len() > u32::MAX as usize {
                return Err(LodSelectError::File(format!("object {:?} has too many levels", o.name)));
            }
            for (level, l) in o.levels.iter().enumerate() {
                let why = if l.benefit.is_nan() {
                    Some("is NaN")
                } else if l.benefit.is_infinite() {
                    Some("is infinite")
                } else if l.benefit < 0.0 {
                    Some("is negative; benefits must be >= 0")
                } else {
                    None
                };
                if let Some(why) = why {
                    return Err(LodSelectError::Benefit {
                        object: o.name.clone(),
                        index,
                        level,
                        value: l.benefit,
                        why,
                    });
                }
            }
            let (level, best) = o
                .levels
                .iter()
                .enumerate()
                .map(|(i, l)| (i, l.benefit))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((0, 0.0));
            best_sum += best;
            if !best_sum.is_finite() {
                return Err(LodSelectError::Benefit {
                    object: o.name.clone(),
                    index,
                    level,
                    value: best,
                    why: "makes the sum of the objects' largest benefits infinite; benefits must add up to a finite number",
                });
            }
        }
        Ok(Instance { budget, objects })
    }

    /// The frame budget.
    pub fn budget(&self) -> Duration {
        self.budget
    }

    /// The objects, in input order.
    pub fn objects(&self) -> &[LodObject] {
        &self.objects
    }

    /// Object tuples (levels) in all.
    pub fn tuples(&self) -> usize {
        self.objects.iter().map(|o| o.levels.len()).sum()
    }

    /// Indices of the objects none of whose levels fits the budget alone
    /// (never drawn by any algorithm).
    pub fn unaffordable(&self) -> Vec<usize> {
        (0..self.objects.len())
            .filter(|&i| self.objects[i].levels.iter().all(|l| l.cost > self.budget))
            .collect()
    }

    /// The level `level` of object `object` (a selection's entry).
    fn level(&self, object: usize, level: Option<u32>) -> (u64, f64) {
        match level {
            Some(l) => {
                let l = &self.objects[object].levels[l as usize];
                (l.cost.0, l.benefit)
            }
            None => (0, 0.0),
        }
    }

    /// Checks a selection's shape against the instance (one entry per
    /// object, each level in range).
    pub fn check_selection(&self, levels: &[Option<u32>]) -> Result<(), LodSelectError> {
        if levels.len() != self.objects.len() {
            return Err(LodSelectError::PreviousLength {
                expected: self.objects.len(),
                got: levels.len(),
            });
        }
        for (index, (o, l)) in self.objects.iter().zip(levels).enumerate() {
            if let Some(l) = *l
                && l as usize >= o.levels.len()
            {
                return Err(LodSelectError::PreviousLevel {
                    object: o.name.clone(),
                    index,
                    level: l,
                    levels: o.levels.len(),
                });
            }
        }
        Ok(())
    }

    /// Runs `algorithm`; `previous` is the incremental algorithm's start
    /// (all objects undrawn when `None`), ignored by the others.
    pub fn select(&self, algorithm: Algorithm, previous: Option<&[Option<u32>]>) -> Result<Selection, LodSelectError> {
        match algorithm {
            Algorithm::Greedy => Ok(greedy(self)),
            Algorithm::Optimal => optimal(self),
            Algorithm::Incremental => match previous {
                Some(p) => incremental(self, p, None),
                None => incremental(self, &vec![None; self.objects.len()], None),
            },
        }
    }
}

/// A selection: per object in input order, the chosen level or `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// Chosen level per object (`None`: not drawn).
    pub levels: Vec<Option<u32>>,
    /// Sum of the chosen levels' costs, exact (never above the budget for a
    /// selection an algorithm returns).
    pub total_cost: u128,
    /// Sum of the chosen levels' benefits, summed in input order.
    pub total_benefit: f64,
}

impl Selection {
    /// The totals of `levels` on `inst` (which must fit its shape, see
    /// [`Instance::check_selection`]).
    pub fn evaluate(inst: &Instance, levels: Vec<Option<u32>>) -> Selection {
        let mut cost = 0u128;
        let mut benefit = 0.0;
        for (i, &l) in levels.iter().enumerate() {
            let (c, b) = inst.level(i, l);
            cost += c as u128;
            benefit += b;
        }
        Selection {
            levels,
            total_cost: cost,
            total_benefit: benefit,
        }
    }

    /// Objects drawn.
    pub fn drawn(&self) -> usize {
        self.levels.iter().filter(|l| l.is_some()).count()
    }
}

/// What `rendersim lod-select` reports: the selection and its totals, the
/// budget, and the optimal benefit beside a heuristic's where it is cheap to
/// find.
#[derive(Debug, Clone, Serialize)]
pub struct SelectionSummary {
    /// The algorithm that made the selection.
    pub algorithm: Algorithm,
    /// Per object in input order: the chosen level index, or null when the
    /// object is not drawn.
    pub selection: Vec<Option<u32>>,
    /// Sum of the chosen levels' costs, in milliseconds.
    pub total_cost_ms: f64,
    /// The same sum in integer picoseconds (exact).
    pub total_cost_ps: u64,
    /// Sum of the chosen levels' benefits.
    pub total_benefit: f64,
    /// The budget, in milliseconds.
    pub budget_ms: f64,
    /// Objects in the instance.
    pub objects: usize,
    /// Objects drawn.
    pub drawn: usize,
    /// Object tuples (levels) in the instance.
    pub tuples: usize,
    /// The optimal total benefit (for greedy and incremental, when the
    /// instance has at most [`MAX_OPTIMAL_OBJECTS`] objects and the search
    /// finished; for optimal, its own).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optimal_benefit: Option<f64>,
    /// `optimal_benefit - total_benefit` (>= 0), where the optimum is known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// Names of the objects none of whose levels fits the budget alone.
    pub unaffordable: Vec<String>,
    /// Notes on edge cases (nothing fits, zero-cost or zero-benefit levels).
    pub notes: Vec<String>,
}

impl SelectionSummary {
    /// Summarizes `sel` (made by `algorithm` on `inst`); `optimum` is the
    /// optimal benefit where known.
    pub fn new(inst: &Instance, algorithm: Algorithm, sel: &Selection, optimum: Option<f64>) -> SelectionSummary {
        let unaffordable: Vec<String> = inst
            .unaffordable()
            .into_iter()
            .map(|i| inst.objects[i].name.clone())
            .collect();
        let mut notes = Vec::new();
        if inst.objects.is_empty() {
            notes.push("the instance has no objects: nothing to select".to_string());
        } else if unaffordable.len() == inst.objects.len() {
            let (i, l, c) = inst
                .objects
                .iter()
                .enumerate()
                .flat_map(|(i, o)| o.levels.iter().enumerate().map(move |(l, x)| (i, l, x.cost)))
                .min_by_key(|t| t.2)
                .unwrap_or((0, 0, Duration::ZERO));
            notes.push(format!(
                "no level of any object fits the budget {}: the cheapest is {:?} level {l} at {c}; nothing is drawn",
                inst.budget, inst.objects[i].name
            ));
        } else if !unaffordable.is_empty() {
            notes.push(format!(
                "{} object(s) cannot be drawn at any level within the budget {}",
                unaffordable.len(),
                inst.budget
            ));
        }
        let zero_benefit = inst
            .objects
            .iter()
            .flat_map(|o| &o.levels)
            .filter(|l| l.benefit == 0.0)
            .count();
        if zero_benefit > 0 {
            notes.push(format!(
                "{zero_benefit} level(s) with zero benefit are never selected (drawing them adds nothing)"
            ));
        }
        let zero_cost = inst
            .objects
            .iter()
            .flat_map(|o| &o.levels)
            .filter(|l| l.cost == Duration::ZERO && l.benefit > 0.0)
            .count();
        if zero_cost > 0 {
            notes.push(format!(
                "{zero_cost} level(s) cost nothing: their value benefit/cost is infinite and they always fit"
            ));
        }
        let cost_ps = u64::try_from(sel.total_cost).unwrap_or(u64::MAX);
        SelectionSummary {
            algorithm,
            selection: sel.levels.clone(),
            total_cost_ms: Duration(cost_ps).as_ms_f64(),
            total_cost_ps: cost_ps,
            total_benefit: sel.total_benefit,
            budget_ms: inst.budget.as_ms_f64(),
            objects: inst.objects.len(),
            drawn: sel.drawn(),
            tuples: inst.tuples(),
            optimal_benefit: optimum,
            gap: optimum.map(|o| (o - sel.total_benefit).max(0.0)),
            unaffordable,
            notes,
        }
    }
}

#[cfg(test)]
mod tests;
