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
use super::config::{FitViews, WalkthroughConfig};
use super::culling::{Pvs, View, features, project, sample_projection};
use super::estimators::{Constants, fit};
use super::lod::Policy;
use super::pos::{PosTable, build as build_table};
use super::render::{Counter, Draw, Renderer};
use super::scene::Scene;
use super::summary::PosTables;
use super::timing::Clock;
use super::validate::MAX_FRAMES;
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
    let mut renders = ExactRenders {
        renderer: exact,
        count,
        empty_gpu: 0.0,
        repeats: cfg.estimation.repeats as usize,
        copies: Vec::with_capacity(cfg.estimation.repeats as usize),
    };
    let (empty, empty_gpu) = renders.render(&[])?;
    renders.empty_gpu = empty_gpu;
    // The clocks the preprocess's renders are read with (timing.rs).
    let (mut fit_clock, mut pos_clock, mut vcs_clock) = (
        clock(cfg, "estimation.clock.fit"),
        clock(cfg, "estimation.clock.pos"),
        clock(cfg, "estimation.clock.vcs"),
    );
    let image = image(cfg);
    let constants = fit_constants(cfg, scene, wants, image, &mut renders, &mut fit_clock)?;
    let (tables, pos_tables) = pos_tables(cfg, scene, wants, policy, image, &mut renders, &mut pos_clock)?;
    let (pvs, view_cells) = view_cells(cfg, scene, poses, wants, &tables, &mut renders, &mut vcs_clock)?;
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

/// The preprocess's renders: exact (run seed 0, at time 0), their events
/// counted; one object's time from `repeats` copies of it.
struct ExactRenders<'a> {
    renderer: &'a Renderer,
    count: &'a mut Counter,
    /// The empty frame's GPU time (ps).
    empty_gpu: f64,
    repeats: usize,
    copies: Vec<Draw>,
}

impl ExactRenders<'_> {
    /// Draws `draws`; returns the rendering and GPU times (ps).
    fn render(&mut self, draws: &[Draw]) -> Result<(f64, f64), SystemError> {
        let (t, by_kind, names) = self.renderer.render_counted(draws, 0, 0)?;
        self.count.add(t.events, &by_kind, names);
        Ok((t.rt as f64, t.gpu as f64))
    }

    /// One object's GPU time read with `clock`: `repeats` copies of `d`
    /// drawn (state set once), the GPU time beyond the empty frame's
    /// divided among them.
    fn object_time(&mut self, d: Draw, clock: &mut Clock) -> Result<f64, SystemError> {
        let mut copies = std::mem::take(&mut self.copies);
        copies.clear();
        copies.resize(self.repeats, d);
        let gpu = self.render(&copies).map(|(_, gpu)| gpu);
        self.copies = copies;
        Ok((clock.read(gpu?) - self.empty_gpu) / self.repeats as f64)
    }
}

/// The estimation's clock for the renders of `stream` (timing.rs).
fn clock(cfg: &WalkthroughConfig, stream: &str) -> Clock {
    let e = &cfg.estimation;
    Clock::new(e.timing, e.clock_overhead, e.clock_noise, cfg.run.seed, stream)
}

/// The camera's image: focal length (pixels), width and height.
fn image(cfg: &WalkthroughConfig) -> (f64, f64, f64) {
    let (w, h) = (cfg.camera.width as f64, cfg.camera.height as f64);
    let focal = 0.5 * w / (0.5 * cfg.camera.fov.to_radians()).tan();
    (focal, w, h)
}

/// The heuristics' constants (when one of h1-h4 is wanted), fitted to
/// single-object renders of random objects, levels and views.
fn fit_constants(
    cfg: &WalkthroughConfig,
    scene: &Scene,
    wants: &[bool],
    (focal, w, h): (f64, f64, f64),
    renders: &mut ExactRenders,
    clock: &mut Clock,
) -> Result<Option<Constants>, SystemError> {
    if !wants[..4].iter().any(|w| *w) {
        return Ok(None);
    }
    if scene.objects.is_empty() {
        return Ok(Some(Constants::default()));
    }
    let alpha_range = super::pos::alphas(&cfg.estimation.pos, focal, w, h);
    let (alpha_lo, alpha_hi) = (alpha_range[0].ln(), alpha_range[alpha_range.len() - 1].ln());
    let streams = RngStreams::new(cfg.run.seed);
    let mut rng = streams.stream("estimation.fit");
    let p = &cfg.estimation.pos;
    let mut walk = match cfg.estimation.fit_views {
        FitViews::LogUniform => None,
        FitViews::Walk => Some(CalibrationWalk::new(
            cfg,
            scene,
            streams.stream("estimation.fit.walk").random(),
        )?),
    };
    let mut samples = Vec::with_capacity(cfg.estimation.fit_samples as usize);
    for _ in 0..cfg.estimation.fit_samples {
        // (The draws keep the order of the log-uniform samples: object,
        // level, size, direction.)
        let (o, level, pr) = match &mut walk {
            Some(walk) => {
                let (o, pr) = walk.sample(cfg, scene, &mut rng)?;
                let level = rng.random_range(0..scene.protos[o.proto as usize].levels.len());
                (o, level, pr)
            }
            None => {
                let o = &scene.objects[rng.random_range(0..scene.objects.len())];
                let proto = &scene.protos[o.proto as usize];
                let level = rng.random_range(0..proto.levels.len());
                let alpha = rng.random_range(alpha_lo..=alpha_hi).exp();
                let gamma = rng.random_range(0.0..std::f64::consts::TAU);
                let phi = rng.random_range(p.phi_min..=p.phi_max).to_radians();
                (o, level, sample_projection(proto, alpha, gamma, phi, focal, w, h))
            }
        };
        let d = Draw {
            proto: o.proto,
            level: level as u32,
            pixels: pr.covered_pixels,
            state: o.state,
        };
        let y = renders.object_time(d, clock)?;
        samples.push((features(scene, o.proto, level, &pr), y));
    }
    Ok(Some(fit(&samples)))
}

/// `estimation.fit_views = "walk"`: a second walk of the camera path's
/// kind, with its own seed, whose poses the fit samples are seen from.
struct CalibrationWalk {
    poses: Vec<Pose>,
    pvs: Pvs,
    visible: Vec<u32>,
}

/// Poses tried for one sample before the walk is declared blind.
const WALK_TRIES: usize = 10_000;

impl CalibrationWalk {
    fn new(cfg: &WalkthroughConfig, scene: &Scene, seed: u64) -> Result<Self, SystemError> {
        if super::camera::resolved_kind(&cfg.camera, scene)? == "keyframes" {
            return Err(invalid(
                "estimation.fit_views",
                "\"walk\" needs a procedural camera path (street, forest or flight): a keyframes path \
                 would walk the recorded path itself, and the fit would see the frames it is tested on",
            ));
        }
        if cfg.camera.speed == Some(0.0) {
            return Err(invalid(
                "estimation.fit_views",
                "\"walk\" needs a moving camera (camera.speed > 0): standing still, the second walk \
                 would see the recorded frames' own view",
            ));
        }
        let dt = cfg.display.refresh.period.0.max(1) as f64 * 1e-12;
        let poses = super::camera::path(&cfg.camera, scene, cfg.run.frames.max(1), dt, seed)?;
        Ok(CalibrationWalk {
            poses,
            pvs: Pvs::default(),
            visible: Vec::new(),
        })
    }

    /// A random object that a random pose of the walk draws, with its
    /// projection there.
    fn sample<'s>(
        &mut self,
        cfg: &WalkthroughConfig,
        scene: &'s Scene,
        rng: &mut impl Rng,
    ) -> Result<(&'s super::scene::Object, super::culling::Projection), SystemError> {
        for _ in 0..WALK_TRIES {
            let pose = self.poses[rng.random_range(0..self.poses.len())];
            let view = View::new(&pose, &cfg.camera);
            self.visible.clear();
            let visible = &mut self.visible;
            self.pvs
                .for_each_visible(scene, pose.eye, &view, cfg.camera.far, |i| visible.push(i));
            if self.visible.is_empty() {
                continue;
            }
            let o = &scene.objects[self.visible[rng.random_range(0..self.visible.len())] as usize];
            return Ok((o, project(&view, o, &scene.protos[o.proto as usize])));
        }
        Err(invalid(
            "estimation.fit_views",
            format!("the calibration walk drew no object from {WALK_TRIES} of its poses"),
        ))
    }
}

/// The pos tables (when pos or pvc is wanted), one per prototype in use,
/// at its finest level (every level when a policy other than "none" draws
/// coarser ones), and what they took.
fn pos_tables(
    cfg: &WalkthroughConfig,
    scene: &Scene,
    wants: &[bool],
    policy: Policy,
    image: (f64, f64, f64),
    renders: &mut ExactRenders,
    clock: &mut Clock,
) -> Result<(Tables, Option<PosTables>), SystemError> {
    let table_levels = |p: &super::scene::Prototype| {
        if policy == Policy::None { 1 } else { p.levels.len() }
    };
    let mut tables: Tables = scene.protos.iter().map(|p| vec![None; table_levels(p)]).collect();
    if !(wants[4] || wants[PVC]) {
        return Ok((tables, None));
    }
    let mut used = vec![false; scene.protos.len()];
    for o in &scene.objects {
        used[o.proto as usize] = true;
    }
    let (mut n_renders, mut full, mut n) = (0u64, 0u64, 0u64);
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
            let (table, r) = build_table(&cfg.estimation.pos, proto, level, image, |_, covered| {
                let d = Draw {
                    proto: i as u32,
                    level: level as u32,
                    pixels: covered,
                    state,
                };
                renders.object_time(d, clock)
            })?;
            n_renders += r;
            full += table.full_size();
            n += 1;
            *slot = Some(table);
        }
    }
    let summary = PosTables {
        tables: n,
        renders: n_renders,
        full_renders: full,
        pruned_fraction: if full > 0 {
            1.0 - n_renders as f64 / full as f64
        } else {
            0.0
        },
    };
    Ok((tables, Some(summary)))
}

/// Per prototype and level, its pos table (none where none was built).
type Tables = Vec<Vec<Option<PosTable>>>;

/// The view-cell estimators (when vcs or pvc is wanted), for the cells the
/// path through `poses` visits, with the potentially visible sets built
/// for them.
fn view_cells(
    cfg: &WalkthroughConfig,
    scene: &Scene,
    poses: &[Pose],
    wants: &[bool],
    tables: &[Vec<Option<PosTable>>],
    renders: &mut ExactRenders,
    clock: &mut Clock,
) -> Result<(Pvs, Option<(ViewCellTables, ViewCellSummary)>), SystemError> {
    let mut pvs = Pvs::default();
    if !(wants[VCS] || wants[PVC]) {
        return Ok((pvs, None));
    }
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
    let n_renders = cells * v.directions as u64 * v.samples as u64;
    if wants[VCS] && n_renders > MAX_FRAMES {
        return Err(invalid(
            "estimation.view_cells.samples",
            format!(
                "{cells} cells x {} directions x {} samples = {n_renders} sample views is more than the limit of {MAX_FRAMES}",
                v.directions, v.samples
            ),
        ));
    }
    let inputs = super::view_cells::Inputs {
        cfg: v,
        cam: &cfg.camera,
        cell,
        poses,
        tables,
        want: (wants[VCS], wants[PVC]),
        seed: cfg.run.seed,
    };
    let built = super::view_cells::build(&inputs, scene, &mut pvs, clock, |draws| {
        renders.render(draws).map(|(rt, _)| rt)
    })?;
    Ok((pvs, Some(built)))
}
