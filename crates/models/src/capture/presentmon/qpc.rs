//! QPC time stamps' tick rate, from what the capture itself implies: the
//! ticks from CPU start to present over `MsCPUBusy`, or one swap chain's
//! consecutive rows' ticks over the milliseconds between them.

use std::collections::HashMap;

use super::cells::{Cells, Notes};
use super::columns::Col;
use super::{CaptureError, DEFAULT_QPC_PER_MS};

/// QPC ticks per millisecond: the median over rows of the ticks from CPU
/// start to present over `MsCPUBusy` (rows busy at least 0.5 ms); `None`
/// where no row is.
pub(super) fn qpc_rate(cell: &Cells<'_>, raw: &[(u64, csv::StringRecord)]) -> Result<Option<f64>, CaptureError> {
    let mut rates = Vec::new();
    for (line, rec) in raw {
        let (Some(start), Some(at), Some(busy)) = (
            cell.opt(rec, *line, Col::CpuStartQpc)?,
            cell.opt(rec, *line, Col::TimeInQpc)?,
            cell.opt(rec, *line, Col::CpuBusy)?,
        ) else {
            continue;
        };
        if busy >= 0.5 && at > start {
            rates.push((at - start) / busy);
        }
    }
    Ok(median(rates))
}

/// A row's ticks, the milliseconds since its swap chain's row before and
/// those to its row after (`None`: the row gives no step).
type Step = Option<(f64, f64, f64)>;

/// QPC ticks per millisecond from one swap chain's consecutive rows: each
/// row gives its ticks, the milliseconds since the chain's row before and
/// those to its row after (one of the two known, the other 0); the median
/// over steps of 0.5 ms or more, `None` without any.
fn rate_of_steps(
    cell: &Cells<'_>,
    raw: &[(u64, csv::StringRecord)],
    read: &dyn Fn(&csv::StringRecord, u64) -> Result<Step, CaptureError>,
) -> Result<Option<f64>, CaptureError> {
    let mut last: HashMap<String, (f64, f64)> = HashMap::new();
    let mut rates = Vec::new();
    for (line, rec) in raw {
        let Some((ticks, since_prev, to_next)) = read(rec, *line)? else {
            continue;
        };
        let chain = cell.text(rec, Col::SwapChain).unwrap_or_default().to_string()
            + cell.text(rec, Col::ProcessId).unwrap_or_default();
        if let Some((t0, to_next0)) = last.insert(chain, (ticks, to_next)) {
            let ms = since_prev + to_next0;
            if ms >= 0.5 && ticks > t0 {
                rates.push((ticks - t0) / ms);
            }
        }
    }
    Ok(median(rates))
}

/// QPC ticks per millisecond of a PresentMon 1 capture timed in ticks
/// (`QPCTime`): one swap chain's tick steps over its `MsBetweenPresents`.
pub(super) fn qpc_rate_v1(file: &str, cell: &Cells<'_>, raw: &[(u64, csv::StringRecord)]) -> Result<f64, CaptureError> {
    let read = |rec: &csv::StringRecord, line: u64| -> Result<Step, CaptureError> {
        Ok(
            match (
                cell.opt(rec, line, Col::TimeInQpc)?,
                cell.opt(rec, line, Col::BetweenPresents)?,
            ) {
                (Some(t), Some(between)) => Some((t, between, 0.0)),
                _ => None,
            },
        )
    };
    rate_of_steps(cell, raw, &read)?.ok_or_else(|| CaptureError::Format {
        file: file.to_string(),
        message: "the QPC tick rate cannot be inferred: no two presents of a swap chain 0.5 ms or more apart".into(),
    })
}

/// QPC ticks per millisecond of a PresentMon 2 capture with `CPUStartQPC`
/// and no `TimeInQPC`: a frame starts when the one before left its present
/// call, so one swap chain's consecutive starts are `MsCPUBusy + MsCPUWait`
/// of the earlier frame apart; QPC's 10 MHz where no two frames give a step.
pub(super) fn qpc_rate_from_starts(
    cell: &Cells<'_>,
    raw: &[(u64, csv::StringRecord)],
    notes: &mut Notes,
) -> Result<f64, CaptureError> {
    let read = |rec: &csv::StringRecord, line: u64| -> Result<Step, CaptureError> {
        let (Some(start), Some(busy)) = (
            cell.opt(rec, line, Col::CpuStartQpc)?,
            cell.opt(rec, line, Col::CpuBusy)?,
        ) else {
            return Ok(None);
        };
        Ok(Some((
            start,
            0.0,
            busy + cell.opt(rec, line, Col::CpuWait)?.unwrap_or(0.0),
        )))
    };
    Ok(match rate_of_steps(cell, raw, &read)? {
        Some(r) => r,
        None => {
            notes.push(format!(
                "`CPUStartQPC` without `TimeInQPC`, and no two frames to infer its rate from: read at {} MHz",
                DEFAULT_QPC_PER_MS / 1e3
            ));
            DEFAULT_QPC_PER_MS
        }
    })
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}
