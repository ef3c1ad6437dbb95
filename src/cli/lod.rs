//! `rendersim lod-select` and `rendersim sortbuf`: paper 001's LOD selection
//! on one knapsack instance and its state-sorting buffer on one sequence
//! (the library's `components::lod_select` and `components::sorting_buffer`).

use super::progress::say;
use std::path::Path;

use anyhow::{Result, bail};

use rendersim::components::lod_select::{
    Algorithm, MAX_OPTIMAL_OBJECTS, SelectionSummary, file::read_instance, optimal,
};
use rendersim::components::sorting_buffer::{SortbufSummary, SortbufSweep, Strategy, sequence::sequence_from_spec};
use rendersim::output::text::fixed;
use rendersim::scene::states::scene_state_ids;

use super::args::{LodSelectArgs, SortbufArgs};

/// `--previous 0,1,-,2`: one entry per object, a level or `-` (not drawn).
fn parse_previous(text: &str) -> Result<Vec<Option<u32>>> {
    if text.trim().is_empty() {
        return Ok(Vec::new());
    }
    text.split(',')
        .enumerate()
        .map(|(i, t)| {
            let t = t.trim();
            if t == "-" || t == "null" {
                Ok(None)
            } else {
                t.parse::<u32>().map(Some).map_err(|_| {
                    anyhow::anyhow!(
                        "--previous: entry {} is {t:?}, expected a level index or - (not drawn)",
                        i + 1
                    )
                })
            }
        })
        .collect()
}

/// `rendersim lod-select`.
pub fn lod_select(args: &LodSelectArgs) -> Result<()> {
    let inst = read_instance(&args.instance)?;
    let algorithm: Algorithm = args.algorithm.into();
    let previous = match &args.previous {
        Some(p) if algorithm != Algorithm::Incremental => {
            bail!("--previous {p:?}: only --algorithm incremental starts from a previous selection")
        }
        Some(p) => Some(parse_previous(p)?),
        None => None,
    };
    let sel = inst.select(algorithm, previous.as_deref())?;
    let optimum = if algorithm == Algorithm::Optimal {
        Some(sel.total_benefit)
    } else if inst.objects().len() <= MAX_OPTIMAL_OBJECTS {
        optimal(&inst).ok().map(|s| s.total_benefit)
    } else {
        None
    };
    let summary = SelectionSummary::new(&inst, algorithm, &sel, optimum);
    if args.json {
        say!("{}", serde_json::to_string_pretty(&summary)?);
        return Ok(());
    }
    say!(
        "{} selection, budget {} ms: {} of {} objects drawn",
        algorithm.name(),
        fixed(summary.budget_ms, 3),
        summary.drawn,
        summary.objects
    );
    let width = inst.objects().iter().map(|o| o.name.len()).max().unwrap_or(6).max(6);
    say!(
        "{:<width$}  {:>5}  {:>10}  {:>10}",
        "object",
        "level",
        "cost ms",
        "benefit"
    );
    for (o, l) in inst.objects().iter().zip(&summary.selection) {
        match l {
            Some(l) => {
                let lv = &o.levels[*l as usize];
                say!(
                    "{:<width$}  {:>5}  {:>10}  {:>10}",
                    o.name,
                    l,
                    fixed(lv.cost.as_ms_f64(), 4),
                    fixed(lv.benefit, 4)
                );
            }
            None => say!("{:<width$}  {:>5}  {:>10}  {:>10}", o.name, "-", "-", "-"),
        }
    }
    say!(
        "total: cost {} ms of {} ms, benefit {}",
        fixed(summary.total_cost_ms, 4),
        fixed(summary.budget_ms, 4),
        fixed(summary.total_benefit, 4)
    );
    if let (Some(opt), Some(gap)) = (summary.optimal_benefit, summary.gap)
        && algorithm != Algorithm::Optimal
    {
        say!("optimal benefit {} (gap {})", fixed(opt, 4), fixed(gap, 4));
    }
    for n in &summary.notes {
        say!("note: {n}");
    }
    Ok(())
}

/// `rendersim sortbuf`.
pub fn sortbuf(args: &SortbufArgs) -> Result<()> {
    let seq = if args.sequence.starts_with("scene:") {
        scene_state_ids(&args.sequence["scene:".len()..], Path::new("."))?
    } else {
        sequence_from_spec(&args.sequence, Path::new("."))?
    };
    let strategies: Vec<Strategy> = args.strategy.iter().map(|&s| s.into()).collect();
    if !args.sweep.is_empty() {
        let strategies = if strategies.is_empty() {
            Strategy::ALL.to_vec()
        } else {
            strategies
        };
        let sweep = SortbufSweep::run(&args.sequence, &seq, &args.sweep, &strategies, args.seed)?;
        if args.json {
            say!("{}", serde_json::to_string_pretty(&sweep)?);
            return Ok(());
        }
        say!(
            "{}: {} elements, {} distinct states, {} changes without a buffer",
            sweep.sequence,
            sweep.sequence_length,
            sweep.distinct_states,
            sweep.input_runs
        );
        let mut head = format!("{:>8}  {:>11}", "buffer", "lower_bound");
        for s in &strategies {
            head.push_str(&format!("  {:>13}", s.name()));
        }
        say!("{head}");
        for r in &sweep.rows {
            let mut line = format!("{:>8}  {:>11}", r.buffer, r.lower_bound);
            for s in &strategies {
                line.push_str(&format!("  {:>13}", r.state_changes[s.name()]));
            }
            say!("{line}");
        }
        return Ok(());
    }
    let Some(k) = args.buffer else {
        bail!("give --buffer K (or --sweep K,K,...)");
    };
    let strategy = match strategies.as_slice() {
        [s] => *s,
        [] => bail!("give --strategy lru|bounded-waste|random|round-robin"),
        _ => bail!("--strategy: give one strategy (several only with --sweep)"),
    };
    let s = SortbufSummary::run(&args.sequence, &seq, k, strategy, args.seed)?;
    if args.json {
        say!("{}", serde_json::to_string_pretty(&s)?);
        return Ok(());
    }
    say!(
        "{} with {} slots over {} ({} elements, {} distinct states): {} state changes; {} without a buffer; offline optimum >= {}{}",
        strategy.name(),
        k,
        s.sequence,
        s.sequence_length,
        s.distinct_states,
        s.state_changes,
        s.input_runs,
        s.lower_bound,
        s.offline_optimum.map(|o| format!(" (exactly {o})")).unwrap_or_default()
    );
    Ok(())
}
