//! `report.md`'s "Beside the paper": every published value a bar plot
//! draws (`paper = [{ where, values }]`) beside the simulated one at each
//! point its `where` selects, with their ratio; then, for each group of
//! points that differ only in what the `where`s fix (a reading swept beside
//! the paper's table, such as Table 6's two fit readings), how many of the
//! published values the simulation comes within a factor of 2 of and the
//! median ratio. The plot shows the same values; this says them in
//! numbers.

use std::fmt::Write as _;

use crate::stats::quantile::quantile;

use super::derived::{ratio, sorted_finite};
use super::report::{cell, fmt_num};
use super::results::ExperimentResult;
use super::spec::{Experiment, PaperValues, PlotKind};
use super::sweep::{Point, expand_points};

/// One published value beside the simulated one at one point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Pair {
    /// The point's index.
    pub point: usize,
    /// The metric path or derived name.
    pub path: String,
    /// Simulated (the replication mean or the derived value).
    pub simulated: Option<f64>,
    /// Published.
    pub paper: f64,
}

impl Pair {
    /// Simulated over published, when both are finite and the published
    /// value is not zero.
    pub fn ratio(&self) -> Option<f64> {
        ratio(self.simulated?, self.paper)
    }
}

/// Every bar plot's published values, beside the simulated ones, in the
/// plots' order, each entry's points in point order and its paths in `y`
/// order.
pub(crate) fn pairs(exp: &Experiment, r: &ExperimentResult, points: &[Point]) -> Vec<Pair> {
    let mut out = Vec::new();
    for (y, paper) in bar_papers(exp) {
        for entry in paper {
            for p in points.iter().filter(|p| p.matches(&entry.filter)) {
                let Some(res) = r.points.get(p.index) else {
                    continue;
                };
                for (path, value) in y.iter().zip(&entry.values) {
                    out.push(Pair {
                        point: p.index,
                        path: path.clone(),
                        simulated: res.value(path),
                        paper: *value,
                    });
                }
            }
        }
    }
    out
}

/// Every bar plot's `y` paths and published values.
fn bar_papers(exp: &Experiment) -> impl Iterator<Item = (&[String], &[PaperValues])> {
    exp.plots.iter().filter_map(|p| match &p.kind {
        PlotKind::Bars { y, paper, .. } => Some((y.as_slice(), paper.as_slice())),
        _ => None,
    })
}

/// How a group of pairs agrees with the paper: the pairs with a ratio, how
/// many of them lie within a factor of 2, and the median ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Agreement {
    /// Pairs with a ratio.
    pub compared: usize,
    /// Of those, within a factor of 2 (ratio in [0.5, 2]).
    pub within_2x: usize,
    /// The median ratio (the mean of the middle two for an even count).
    pub median: f64,
}

/// The agreement of `ratios`, `None` when there are none.
pub(crate) fn agreement(ratios: &[f64]) -> Option<Agreement> {
    let r = sorted_finite(ratios)?;
    Some(Agreement {
        compared: r.len(),
        within_2x: r.iter().filter(|v| (0.5..=2.0).contains(*v)).count(),
        median: quantile(&r, 0.5),
    })
}

/// The section, or nothing when no bar plot carries published values.
pub(crate) fn section(s: &mut String, exp: &Experiment, r: &ExperimentResult) {
    let points = expand_points(exp);
    let pairs = pairs(exp, r, &points);
    if pairs.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "## Beside the paper\n\nEvery published value the bar plots draw, beside the simulated one at each \
         point its `where` selects.\n\n| point | value | simulated | paper | simulated / paper |\n|---|---|---|---|---|"
    );
    for q in &pairs {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            cell(&r.points[q.point].label),
            cell(&exp.label_of(&q.path)),
            q.simulated.map(fmt_num).unwrap_or_else(|| "n/a".into()),
            fmt_num(q.paper),
            q.ratio().map(|v| format!("{v:.3}x")).unwrap_or_else(|| "n/a".into()),
        );
    }
    // Groups: the points' assignments less the keys the `where`s fix.
    let fixed: Vec<&str> = bar_papers(exp)
        .flat_map(|(_, paper)| paper)
        .flat_map(|e| e.filter.iter().map(|(k, _)| k.as_str()))
        .collect();
    let group_of = |i: usize| -> String {
        let parts: Vec<String> = r.points[i]
            .assignments
            .iter()
            .filter(|(k, _)| !fixed.contains(&k.as_str()))
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        if parts.is_empty() {
            "all points".into()
        } else {
            parts.join(", ")
        }
    };
    let mut groups: Vec<(String, Vec<f64>)> = Vec::new();
    for q in &pairs {
        let g = group_of(q.point);
        let qr = q.ratio();
        match groups.iter_mut().find(|(name, _)| *name == g) {
            Some((_, v)) => v.extend(qr),
            None => groups.push((g, qr.into_iter().collect())),
        }
    }
    let _ = writeln!(
        s,
        "\n| points | values compared | within a factor of 2 | median simulated / paper |\n|---|---|---|---|"
    );
    for (g, ratios) in &groups {
        match agreement(ratios) {
            Some(a) => {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {:.3}x |",
                    cell(g),
                    a.compared,
                    a.within_2x,
                    a.median
                );
            }
            None => {
                let _ = writeln!(s, "| {} | 0 | | |", cell(g));
            }
        }
    }
    s.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreement_counts_the_factor_of_2_and_takes_the_middle() {
        let a = agreement(&[0.19, 0.82, 0.39, 2.1, 0.25, 1.2, 1.11, 0.01, 0.0035, 0.016]).unwrap();
        assert_eq!(a.compared, 10);
        // 0.82, 1.2 and 1.11 lie in [0.5, 2]; 2.1 does not.
        assert_eq!(a.within_2x, 3);
        // Sorted, the middle two are 0.25 and 0.39.
        assert!((a.median - 0.32).abs() < 1e-12);
        let odd = agreement(&[4.0, 0.5, 1.0]).unwrap();
        assert_eq!((odd.within_2x, odd.median), (2, 1.0));
        assert_eq!(agreement(&[f64::NAN]), None);
        assert_eq!(agreement(&[]), None);
    }

    #[test]
    fn a_pair_has_no_ratio_against_zero_or_without_a_value() {
        let p = |simulated, paper| Pair {
            point: 0,
            path: "m".into(),
            simulated,
            paper,
        };
        assert_eq!(p(Some(3.0), 1.5).ratio(), Some(2.0));
        assert_eq!(p(Some(3.0), 0.0).ratio(), None);
        assert_eq!(p(None, 1.0).ratio(), None);
    }
}
