//! A capture's rows as its writer meant them in time: one recording where
//! the clock restarts, and each swap chain's presents in time order
//! (PresentMon writes rows as frames complete, not in time order across
//! swap chains or within one), PresentMon 1's CPU starts filled in.

use std::collections::HashMap;

use super::cells::Notes;
use super::{Columns, Present, RESTART_MS, Row};

/// The rows of the longest recording, where the capture's clock restarts
/// (a swap chain's present goes back more than [`RESTART_MS`]).
pub(super) fn one_recording(rows: Vec<Row>, notes: &mut Notes) -> Vec<Row> {
    let mut last: HashMap<(&str, &str, &str), f64> = HashMap::new();
    let mut starts = vec![0usize];
    let mut backs = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let p = &r.present;
        if let Some(&l) = last.get(&p.chain())
            && p.present < l - RESTART_MS
        {
            starts.push(i);
            backs.push((p.line, (l - p.present) / 1e3));
            last.clear();
        }
        last.insert(p.chain(), p.present);
    }
    if starts.len() == 1 {
        return rows;
    }
    starts.push(rows.len());
    let (a, b) = starts
        .windows(2)
        .map(|w| (w[0], w[1]))
        .max_by_key(|&(a, b)| (b - a, std::cmp::Reverse(a)))
        .expect("two segments at least");
    notes.push(format!(
        "the clock restarts {} time(s) (line {} goes back {:.1} s): {} recordings; read the one with most rows, lines {}-{}",
        backs.len(),
        backs[0].0,
        backs[0].1,
        starts.len() - 1,
        rows[a].present.line,
        rows[b - 1].present.line
    ));
    rows.into_iter().skip(a).take(b - a).collect()
}

/// Each swap chain's presents in time order (file order where they tie),
/// the swap chains interleaved as in the file; PresentMon 1's CPU starts
/// filled in (the previous present call's end, the first frame's
/// `MsBetweenPresents` before its present).
pub(super) fn in_time_order(rows: Vec<Row>, columns: Columns, notes: &mut Notes) -> Vec<Present> {
    // Each row's swap chain, numbered in order of first appearance.
    let mut ids: HashMap<(&str, &str, &str), usize> = HashMap::new();
    let chain_of: Vec<usize> = rows
        .iter()
        .map(|r| {
            let n = ids.len();
            *ids.entry(r.present.chain()).or_insert(n)
        })
        .collect();
    let mut by_chain: Vec<Vec<usize>> = vec![Vec::new(); ids.len()];
    drop(ids);
    for (i, &c) in chain_of.iter().enumerate() {
        by_chain[c].push(i);
    }
    // Slot i of the output takes the present that belongs there once its
    // swap chain's rows are sorted (the slots a swap chain fills stay its own).
    let mut slot: Vec<usize> = (0..rows.len()).collect();
    let mut out_of_order = 0;
    for idx in &by_chain {
        let mut sorted = idx.clone();
        sorted.sort_by(|&a, &b| {
            rows[a]
                .present
                .present
                .total_cmp(&rows[b].present.present)
                .then(a.cmp(&b))
        });
        out_of_order += idx.iter().zip(&sorted).filter(|(a, b)| a != b).count();
        for (&s, &from) in idx.iter().zip(&sorted) {
            slot[s] = from;
        }
    }
    if out_of_order > 0 {
        notes.push(format!(
            "{out_of_order} row(s) were out of time order within their swap chain: read in the order of their presents"
        ));
    }
    let mut taken: Vec<Option<Row>> = rows.into_iter().map(Some).collect();
    let mut out: Vec<(Present, f64)> = slot
        .iter()
        .map(|&from| {
            let r = taken[from].take().expect("each row placed once");
            (r.present, r.between)
        })
        .collect();
    if columns == Columns::V1 {
        // The previous present and its time in the present call, per chain
        // (slot s holds a row of the chain of the row first at s).
        let mut prev: Vec<Option<(f64, f64)>> = vec![None; by_chain.len()];
        for (s, (p, between)) in out.iter_mut().enumerate() {
            let c = chain_of[s];
            let start = match prev[c] {
                Some((pp, w)) => pp + w,
                None => p.present - *between,
            };
            prev[c] = Some((p.present, p.cpu_wait));
            p.cpu_start = start.min(p.present);
            p.cpu_busy = (p.present - p.cpu_start).max(0.0);
        }
    }
    out.into_iter().map(|(p, _)| p).collect()
}
