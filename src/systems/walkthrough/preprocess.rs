//! The walkthrough's preprocess, before the first frame (paper 000 §6.1-6.2
//! and §5.1-5.2): the empty frame, the single-object renders the heuristics
//! h1-h4 are fitted to, the per-object sampling (pos) tables, and the
//! view-cell estimators (vcs, pvc) for the cells the camera path visits.
//! Every render is exact (system tasks off) and read through its own clock
//! (`timing.rs`): GPU time stamps, or a CPU clock around a finish.

use rand::Rng;

use crate::engine::RngStreams;
use crate::systems::error::{SystemError, invalid};

use super::camera::Pose;
use super::config::WalkthroughConfig;
use super::culling::{Pvs, sample_projection};
use super::estimators::{Constants, fit};
use super::lod::Policy;
use super::pos::{PosTable, build as build_table};
use super::render::{Draw, Renderer};
use super::run::{Counter, MAX_FRAMES, features};
use super::scene::Scene;
use super::summary::PosTables;
use super::timing::Clock;
use super::view_cells::{PVC, VCS, ViewCellSummary, ViewCellTables};

/// What the preprocess built, for the frames and the summary.
pub(super) struct Preprocess {
    /// Rendering time of an empty frame (ps): the frame's own terms, added
    /// to every per-object estimate.
    pub empty: f64,
    /// h1-h4's fitted constants (none when no heuristic is estimated).
    pub constants: Option<Constants>,
    /// Per prototype and level, its pos table (where pos or pvc needs one).
    pub tables: Vec<Vec<Option<PosTable>>>,
    /// What the pos tables took (none without pos and pvc).
    pub pos_tables: Option<PosTables>,
    /// The potentially visible sets of the view cells visited so far.
    pub pvs: Pvs,
    /// The view-cell estimators' tables and their summary.
    pub view_cells: Option<(ViewCellTables, ViewCellSummary)>,
    /// Clock readings taken (fit, pos and vcs renders together).
    pub clock_readings: u64,
}

/// Runs the preprocess for the estimators in `wants` (indexed as
/// [`super::estimators::ESTIMATORS`]) and the LOD `policy` (which decides
/// whether coarser levels get pos tables too), counting the exact
/// renderer's events in `count`.
pub(super) fn preprocess(
    cfg: &WalkthroughConfig,
    scene: &Scene,
    poses: &[Pose],
    exact: &Renderer,
    wants: &[bool],
    policy: Policy,
    count: &mut Counter,
) -> Result<Preprocess, SystemError> {
    let render_exact = |draws: &[Draw], count: &mut Counter| -> Result<(f64, f64), SystemError> {
        let (t, by_kind, names) = exact.render_counted(draws, 0, 0)?;
        count.add(t.events, &by_kind, names);
        Ok((t.rt as f64, t.gpu as f64))
    };
    let (empty, empty_gpu) = render_exact(&[], count)?;
    // The clocks the preprocess's renders are read with (timing.rs).
    let est_cfg = &cfg.estimation;
    let clock = |stream: &str| {
        Clock::new(
            est_cfg.timing,
            est_cfg.clock_overhead,
            est_cfg.clock_noise,
            cfg.run.seed,
            stream,
        )
    };
    let (mut fit_clock, mut pos_clock, mut vcs_clock) = (
        clock("estimation.clock.fit"),
        clock("estimation.clock.pos"),
        clock("estimation.clock.vcs"),
    );
    // One object's GPU time: `repeats` copies drawn (state set once), the
    // GPU time beyond the empty frame's divided among them.
    let repeats = cfg.estimation.repeats as usize;
    let mut copies: Vec<Draw> = Vec::with_capacity(repeats);
    let mut object_time = |d: Draw, count: &mut Counter, clock: &mut Clock| -> Result<f64, SystemError> {
        copies.clear();
        copies.resize(repeats, d);
        let (_, gpu) = render_exact(&copies, count)?;
        Ok((clock.read(gpu) - empty_gpu) / repeats as f64)
    };
    let (w, h) = (cfg.camera.width as f64, cfg.camera.height as f64);
    let focal = 0.5 * w / (0.5 * cfg.camera.fov.to_radians()).tan();
    let alpha_range = super::pos::alphas(&cfg.estimation.pos, focal, w, h);
    let (alpha_lo, alpha_hi) = (alpha_range[0].ln(), alpha_range[alpha_range.len() - 1].ln());

    // The heuristics' constants, fitted to single-object renders.
    let constants = if wants[..4].iter().any(|w| *w) && !scene.objects.is_empty() {
        let mut rng = RngStreams::new(cfg.run.seed).stream("estimation.fit");
        let p = &cfg.estimation.pos;
        let mut samples = Vec::with_capacity(cfg.estimation.fit_samples as usize);
        for _ in 0..cfg.estimation.fit_samples {
            let o = &scene.objects[rng.random_range(0..scene.objects.len())];
            let proto = &scene.protos[o.proto as usize];
            let level = rng.random_range(0..proto.levels.len());
            let alpha = rng.random_range(alpha_lo..=alpha_hi).exp();
            let gamma = rng.random_range(0.0..std::f64::consts::TAU);
            let phi = rng.random_range(p.phi_min..=p.phi_max).to_radians();
            let pr = sample_projection(proto, alpha, gamma, phi, focal, w, h);
            let d = Draw {
                proto: o.proto,
                level: level as u32,
                pixels: pr.covered_pixels,
                state: o.state,
            };
            let y = object_time(d, count, &mut fit_clock)?;
            samples.push((features(scene, o.proto, level, &pr), y));
        }
        Some(fit(&samples))
    } else if wants[..4].iter().any(|w| *w) {
        Some(Constants::default())
    } else {
        None
    };

    // The pos tables, one per prototype in use, at its finest level (every
    // level when a policy other than "none" draws coarser ones).
    let table_levels = |p: &super::scene::Prototype| {
        if policy == Policy::None { 1 } else { p.levels.len() }
    };
    let mut tables: Vec<Vec<Option<PosTable>>> = scene.protos.iter().map(|p| vec![None; table_levels(p)]).collect();
    let mut pos_tables = None;
    if wants[4] || wants[PVC] {
        let mut used = vec![false; scene.protos.len()];
        for o in &scene.objects {
            used[o.proto as usize] = true;
        }
        let (mut renders, mut full, mut n) = (0u64, 0u64, 0u64);
        for (i, proto) in scene.protos.iter().enumerate() {
            if !used[i] {
                continue;
            }
            let state = scene
                .objects
                .iter()
                .find(|o| o.proto as usize == i)
                .map_or((0, 0, 0), |o| o.state);
            for (level, slot) in tables[i].iter_mut().enumerate() {
                let (table, r) = build_table(&cfg.estimation.pos, proto, level, (focal, w, h), |_, covered| {
                    let d = Draw {
                        proto: i as u32,
                        level: level as u32,
                        pixels: covered,
                        state,
                    };
                    object_time(d, count, &mut pos_clock)
                })?;
                renders += r;
                full += table.full_size();
                n += 1;
                *slot = Some(table);
            }
        }
        pos_tables = Some(PosTables {
            tables: n,
            renders,
            full_renders: full,
            pruned_fraction: if full > 0 {
                1.0 - renders as f64 / full as f64
            } else {
                0.0
            },
        });
    }
    // The view-cell estimators, for the cells the path visits.
    let mut pvs = Pvs::default();
    let mut view_cells: Option<(ViewCellTables, ViewCellSummary)> = None;
    if wants[VCS] || wants[PVC] {
        let Some(cell) = scene.view_cell else {
            let i = cfg
                .estimation
                .estimators
                .iter()
                .position(|e| e == "vcs" || e == "pvc")
                .unwrap_or(0);
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!(
                    "{:?} needs view cells (the city preset, or scene.view_cell > 0 with listed objects)",
                    cfg.estimation.estimators[i]
                ),
            ));
        };
        let cells = super::view_cells::visited(poses, cell).len() as u64;
        let v = &cfg.estimation.view_cells;
        let renders = cells * v.directions as u64 * v.samples as u64;
        if wants[VCS] && renders > MAX_FRAMES {
            return Err(invalid(
                "estimation.view_cells.samples",
                format!(
                    "{cells} cells x {} directions x {} samples = {renders} sample views is more than the limit of {MAX_FRAMES}",
                    v.directions, v.samples
                ),
            ));
        }
        let inputs = super::view_cells::Inputs {
            cfg: v,
            cam: &cfg.camera,
            cell,
            poses,
            tables: &tables,
            want: (wants[VCS], wants[PVC]),
            seed: cfg.run.seed,
        };
        view_cells = Some(super::view_cells::build(
            &inputs,
            scene,
            &mut pvs,
            &mut vcs_clock,
            |draws| render_exact(draws, count).map(|(rt, _)| rt),
        )?);
    }
    Ok(Preprocess {
        empty,
        constants,
        tables,
        pos_tables,
        pvs,
        view_cells,
        clock_readings: fit_clock.readings() + pos_clock.readings() + vcs_clock.readings(),
    })
}
