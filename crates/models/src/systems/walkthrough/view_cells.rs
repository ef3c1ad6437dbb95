//! The view-cell estimators of paper 000 §5.1-5.2, both built in a
//! preprocess for each view cell and each discretized view direction, and
//! looked up at run time by the eye's cell and the heading's direction:
//!
//! - `vcs`, view-cell sampling (§5.1): `estimation.view_cells.samples`
//!   views are drawn at random inside the cell around the direction (eye
//!   uniform in the cell, heading uniform in the direction's sector,
//!   height and pitch uniform in the path's ranges), each rendered alone
//!   through the frame pipeline (system tasks off) and timed as the
//!   model's `estimation.timing` says; the largest of their rendering times
//!   RT is the estimate (it gives RT directly).
//! - `pvc`, per-view-cell estimation (§5.2): for each object of the cell's
//!   PVS that some view of the cell and direction may see, the largest
//!   screen size its bounding sphere can take from the cell, and the pos
//!   table's largest entry at that size over the directions the object can
//!   be seen from; the estimate is the sum (plus the frame's own terms, as
//!   for pos). It bounds the per-viewpoint pos estimate of every view in
//!   the cell and direction, so it never estimates less than pos does.
//!
//! The view cell: the PVS's square cell (`scene.view_cell`, the city's
//! 10 m) extruded over the heights the recorded path's eye takes; view
//! directions: headings in `directions` equal sectors (sector k centred on
//! k · 2π / directions), pitches in the range the path takes (the
//! navigation's freedom). Only the cells the path visits are built (the
//! city has about 90,000 cells, the path crosses a few dozen; the summary
//! reports both).
//!
//! The largest screen size (the paper: the boundary point where the sphere
//! appears largest in the frustum, on a vertex of the cell or where the
//! frustum is tangent to the sphere) is bounded here without a search,
//! from three lower bounds over the cell and the direction's views: the
//! eye's distance d to the sphere's centre (the nearest point of the cell),
//! the horizontal angle between heading and the object's direction (the
//! sector against the directions from the cell's corners) and the
//! elevation difference. Together they bound the angle β between the view
//! axis and the object from below, hence the distance of the sphere's disk
//! from the screen centre (f · d sin β / max(d cos β, R), the projection of
//! `culling.rs`); the disk of the nearest distance's radius at that offset,
//! clipped to the viewport (the largest over 17 offset directions: the
//! clipped area falls along every ray from the centre, by Brunn-Minkowski),
//! is the bound. An object is left out when β's bound exceeds the frustum's
//! half-diagonal angle plus the angle of R / sin ψ at distance d, ψ the
//! smaller half field of view: the centres the frustum's plane test keeps
//! (within R of each side plane) lie in the frustum's pyramid moved back by
//! R / sin ψ along the axis, so within that distance of the pyramid.

use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

use rand::Rng;
use serde::Serialize;

use crate::engine::{RngStreams, StreamRng};
use crate::systems::error::SystemError;

use super::camera::Pose;
use super::config::{CameraConfig, PvcReading, ViewCellEstimation};
use super::culling::{Pvs, View, alpha_of_disk, disk_in_rect, project};
use super::pos::PosTable;
use super::render::Draw;
use super::scene::{Object, Scene};
use super::timing::Clock;

/// Index of `vcs` in [`super::estimators::ESTIMATORS`].
pub const VCS: usize = 5;
/// Index of `pvc` in [`super::estimators::ESTIMATORS`].
pub const PVC: usize = 6;

/// A view cell's grid key (as the PVS keys its cells).
pub type CellKey = (i64, i64);

/// The cell holding `eye`.
pub fn cell_key(eye: [f64; 3], cell: f64) -> CellKey {
    ((eye[0] / cell).floor() as i64, (eye[1] / cell).floor() as i64)
}

/// The direction sector of heading `yaw` (radians).
pub fn bin_of(yaw: f64, directions: u32) -> usize {
    let n = directions.max(1) as usize;
    let x = yaw.rem_euclid(TAU) / (TAU / n as f64);
    (x.round() as usize) % n
}

/// What the navigation allows: eye heights and pitches (radians) of the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nav {
    /// Lowest and highest eye height.
    pub z: (f64, f64),
    /// Lowest and highest pitch.
    pub pitch: (f64, f64),
}

impl Nav {
    /// The ranges the poses take.
    pub fn of(poses: &[Pose]) -> Nav {
        let mut n = Nav {
            z: (f64::INFINITY, f64::NEG_INFINITY),
            pitch: (f64::INFINITY, f64::NEG_INFINITY),
        };
        for p in poses {
            n.z = (n.z.0.min(p.eye[2]), n.z.1.max(p.eye[2]));
            n.pitch = (n.pitch.0.min(p.pitch), n.pitch.1.max(p.pitch));
        }
        n
    }
}

/// The cells the poses visit, in order of first visit.
pub fn visited(poses: &[Pose], cell: f64) -> Vec<CellKey> {
    let mut seen = std::collections::HashSet::new();
    poses
        .iter()
        .map(|p| cell_key(p.eye, cell))
        .filter(|k| seen.insert(*k))
        .collect()
}

/// One random view in cell `key` (side `cell`) and direction sector `bin`.
pub fn sample_pose(key: CellKey, cell: f64, bin: usize, directions: u32, nav: &Nav, rng: &mut StreamRng) -> Pose {
    let sector = TAU / directions.max(1) as f64;
    let u = |rng: &mut StreamRng, lo: f64, hi: f64| if hi > lo { rng.random_range(lo..=hi) } else { lo };
    let x = u(rng, 0.0, 1.0);
    let y = u(rng, 0.0, 1.0);
    let z = u(rng, nav.z.0, nav.z.1);
    let yaw = bin as f64 * sector + u(rng, -0.5, 0.5) * sector;
    let pitch = u(rng, nav.pitch.0, nav.pitch.1);
    Pose {
        eye: [(key.0 as f64 + x) * cell, (key.1 as f64 + y) * cell, z],
        yaw,
        pitch,
    }
}

/// View-cell sampling's rule: the largest of `n` sampled rendering times
/// (`time(i)` times sample view `i`).
pub fn max_of_samples(n: u32, mut time: impl FnMut(u32) -> Result<f64, SystemError>) -> Result<f64, SystemError> {
    let mut best = 0.0f64;
    for i in 0..n {
        best = best.max(time(i)?);
    }
    Ok(best)
}

/// The view's constants the bounds need.
#[derive(Debug, Clone, Copy)]
pub struct Lens {
    /// Focal length, pixels.
    pub focal: f64,
    /// Viewport width and height, pixels.
    pub w: f64,
    /// Viewport height, pixels.
    pub h: f64,
    /// Far plane, metres.
    pub far: f64,
    /// Half the diagonal field of view, radians.
    pub half_diagonal: f64,
    /// 1 / sin of the smaller half field of view: how far (in radii) a
    /// centre the plane test keeps may lie from the frustum's pyramid.
    pub reach: f64,
}

impl Lens {
    /// The lens of a camera.
    pub fn of(cam: &CameraConfig) -> Lens {
        let (w, h) = (cam.width as f64, cam.height as f64);
        let focal = 0.5 * w / (0.5 * cam.fov.to_radians()).tan();
        Lens {
            focal,
            w,
            h,
            far: cam.far,
            half_diagonal: ((0.5 * w).hypot(0.5 * h) / focal).atan(),
            reach: 1.0 / (0.5 * w.min(h) / focal).atan().sin(),
        }
    }
}

/// What an object can look like from a cell and direction: its largest
/// clipped α and the intervals of its azimuth γ and elevation φ (object
/// frame, radians) seen from the cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Largest α (clipped to the viewport).
    pub alpha: f64,
    /// Largest clipped disk, pixels.
    pub pixels: f64,
    /// Azimuths `[lo, hi]` (`hi - lo >= 2π`: all).
    pub gamma: (f64, f64),
    /// Elevations `[lo, hi]`.
    pub phi: (f64, f64),
}

fn wrap(a: f64) -> f64 {
    (a + PI).rem_euclid(TAU) - PI
}

/// The bound of object `o` from cell `key` (side `cell`) in direction
/// sector `bin` of `directions`, or `None` when no view of the cell and
/// direction can see it.
pub fn object_bound(
    o: &Object,
    key: CellKey,
    cell: f64,
    bin: usize,
    directions: u32,
    nav: &Nav,
    lens: &Lens,
) -> Option<Bound> {
    let (x0, y0) = (key.0 as f64 * cell, key.1 as f64 * cell);
    let (x1, y1) = (x0 + cell, y0 + cell);
    let c = o.center;
    let r = o.radius;
    // Horizontal distances from the cell's square.
    let dx = (x0 - c[0]).max(c[0] - x1).max(0.0);
    let dy = (y0 - c[1]).max(c[1] - y1).max(0.0);
    let h_min = dx.hypot(dy);
    let corners = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
    let h_max = corners
        .iter()
        .map(|(x, y)| (c[0] - x).hypot(c[1] - y))
        .fold(0.0f64, f64::max);
    let dz = (nav.z.0 - c[2]).max(c[2] - nav.z.1).max(0.0);
    let d_min = h_min.hypot(dz);
    // Directions from the cell to the centre (relative to the cell centre's).
    let inside_xy = h_min <= 0.0;
    let theta_mid = (c[1] - 0.5 * (y0 + y1)).atan2(c[0] - 0.5 * (x0 + x1));
    let (lo, hi) = if inside_xy {
        (-PI, PI)
    } else {
        corners
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), (x, y)| {
                let a = wrap((c[1] - y).atan2(c[0] - x) - theta_mid);
                (l.min(a), u.max(a))
            })
    };
    let sector = TAU / directions.max(1) as f64;
    let delta_min = if inside_xy || directions <= 1 {
        0.0
    } else {
        let b = wrap(bin as f64 * sector - theta_mid);
        [b - TAU, b, b + TAU]
            .iter()
            .map(|b| (lo - (b + 0.5 * sector)).max((b - 0.5 * sector) - hi).max(0.0))
            .fold(f64::INFINITY, f64::min)
            .min(PI)
    };
    // Elevations of the centre from the cell's eyes (extremes at corners of
    // the (height, distance) box: monotone in each).
    let mut e = (f64::INFINITY, f64::NEG_INFINITY);
    for z in [nav.z.0, nav.z.1] {
        for hd in [h_min, h_max] {
            let v = (c[2] - z).atan2(hd);
            e = (e.0.min(v), e.1.max(v));
        }
    }
    let eps = (nav.pitch.0 - e.1).max(e.0 - nav.pitch.1).max(0.0);
    let cos_min = |a: (f64, f64)| a.0.cos().min(a.1.cos()).max(0.0);
    // cos β = cos(e1 - e2) - cos e1 cos e2 (1 - cos δ), bounded above.
    let cos_beta = eps.cos() - cos_min(e) * cos_min(nav.pitch) * (1.0 - delta_min.cos());
    let beta_min = cos_beta.clamp(-1.0, 1.0).acos();
    let inside = d_min <= r;
    let margin = if inside {
        PI
    } else {
        (lens.reach * r / d_min).min(1.0).asin()
    };
    let beta_cap = (lens.half_diagonal + margin).min(PI);
    if beta_min > beta_cap {
        return None;
    }
    if !inside && d_min * beta_cap.min(FRAC_PI_2).cos() - r > lens.far {
        return None;
    }
    let pixels = if inside {
        lens.w * lens.h
    } else {
        let rad = lens.focal * r / (d_min * d_min - r * r).sqrt();
        let s = |b: f64| lens.focal * d_min * b.sin() / (d_min * b.cos()).max(r);
        let off = s(beta_min).min(s(beta_cap));
        (0..17)
            .map(|k| {
                let w = FRAC_PI_2 * k as f64 / 16.0;
                disk_in_rect(
                    0.5 * lens.w + off * w.cos(),
                    0.5 * lens.h + off * w.sin(),
                    rad,
                    lens.w,
                    lens.h,
                )
            })
            .fold(0.0f64, f64::max)
    };
    // Azimuths of the eyes seen from the object (its frame), elevations.
    let gamma = if inside_xy {
        (0.0, TAU)
    } else {
        let base = theta_mid + PI - o.yaw;
        (base + lo, base + hi)
    };
    Some(Bound {
        alpha: alpha_of_disk(pixels, lens.focal),
        pixels,
        gamma,
        phi: (-e.1, -e.0),
    })
}

/// Points per side of the grid searched on each face of a view cell
/// ([`PvcReading::Point`]): 9 x 9 on each of the six faces of the cell's
/// box (its square extruded over the path's eye heights).
pub const BOUNDARY_GRID: usize = 9;

/// The views [`PvcReading::Point`] searches for cell `key` and direction
/// `bin`: the sector's centre heading and the path's middle pitch, from each
/// point of a [`BOUNDARY_GRID`] grid on each face of the cell's box.
pub fn boundary_views(
    key: CellKey,
    cell: f64,
    bin: usize,
    directions: u32,
    nav: &Nav,
    cam: &CameraConfig,
) -> Vec<View> {
    let (x0, y0) = (key.0 as f64 * cell, key.1 as f64 * cell);
    let lo = [x0, y0, nav.z.0];
    let hi = [x0 + cell, y0 + cell, nav.z.1];
    let yaw = bin as f64 * TAU / directions.max(1) as f64;
    let pitch = 0.5 * (nav.pitch.0 + nav.pitch.1);
    let n = BOUNDARY_GRID;
    let at = |a: usize, i: usize| lo[a] + (hi[a] - lo[a]) * i as f64 / (n - 1) as f64;
    let mut views = Vec::with_capacity(6 * n * n);
    for fixed in 0..3 {
        let (a, b) = ((fixed + 1) % 3, (fixed + 2) % 3);
        for side in [lo[fixed], hi[fixed]] {
            for i in 0..n {
                for j in 0..n {
                    let mut eye = [0.0; 3];
                    eye[fixed] = side;
                    eye[a] = at(a, i);
                    eye[b] = at(b, j);
                    views.push(View::new(&Pose { eye, yaw, pitch }, cam));
                }
            }
        }
    }
    views
}

/// The projection of `o` from the view where its bounding sphere appears
/// largest in the frustum (largest clipped α) among `views`, or `None` when
/// no view sees it.
pub fn largest_point(
    views: &[View],
    o: &Object,
    proto: &super::scene::Prototype,
) -> Option<super::culling::Projection> {
    views
        .iter()
        .filter(|v| v.sees_sphere(o.center, o.radius))
        .map(|v| project(v, o, proto))
        .max_by(|a, b| a.alpha.total_cmp(&b.alpha))
}

/// `metrics.estimation.view_cells`: the view-cell preprocess and its cost.
#[derive(Debug, Clone, Serialize)]
pub struct ViewCellSummary {
    /// Discretized view directions per cell.
    pub directions: u32,
    /// Cells built: those the path visits.
    pub cells: u64,
    /// Cells of the scene's grid (its objects' extent), built or not.
    pub cells_in_grid: u64,
    /// `vcs`: sample views per cell and direction.
    pub samples: u32,
    /// `vcs`: sample views rendered.
    pub vcs_renders: u64,
    /// `vcs`: wall time of the preprocess, seconds (machine dependent).
    pub vcs_preprocess_seconds: f64,
    /// `pvc`: object bounds computed (objects x directions x cells).
    pub pvc_bounds: u64,
    /// `pvc`: pos-table entries read by the bounds.
    pub pvc_table_reads: u64,
    /// `pvc`: wall time of the preprocess, seconds (machine dependent).
    pub pvc_preprocess_seconds: f64,
}

/// The built tables: per cell, per direction, the estimate (picoseconds;
/// `vcs` the whole RT, `pvc` the sum of the objects' GPU times).
#[derive(Debug, Default)]
pub struct ViewCellTables {
    directions: u32,
    cell: f64,
    vcs: HashMap<CellKey, Vec<f64>>,
    pvc: HashMap<CellKey, Vec<f64>>,
}

impl ViewCellTables {
    /// The estimate of `which` ([`VCS`] or [`PVC`]) for a pose, picoseconds
    /// (0 for a cell that was not built).
    pub fn lookup(&self, which: usize, pose: &Pose) -> f64 {
        let t = if which == VCS { &self.vcs } else { &self.pvc };
        t.get(&cell_key(pose.eye, self.cell))
            .map_or(0.0, |v| v[bin_of(pose.yaw, self.directions)])
    }
}

/// The draws of one view: the cell's PVS (`candidates`) culled to the
/// frustum, each object at its finest level.
pub fn view_draws(scene: &Scene, candidates: &[u32], pose: &Pose, cam: &CameraConfig, draws: &mut Vec<Draw>) {
    let view = View::new(pose, cam);
    draws.clear();
    for &i in candidates {
        let o = &scene.objects[i as usize];
        if view.sees_sphere(o.center, o.radius) {
            let p = project(&view, o, &scene.protos[o.proto as usize]);
            draws.push(Draw {
                proto: o.proto,
                level: 0,
                pixels: p.covered_pixels,
                state: o.state,
            });
        }
    }
}

/// What [`build`] needs besides the scene.
pub struct Inputs<'a> {
    /// The estimators' keys.
    pub cfg: &'a ViewCellEstimation,
    /// The camera.
    pub cam: &'a CameraConfig,
    /// The view-cell size, metres.
    pub cell: f64,
    /// The path.
    pub poses: &'a [Pose],
    /// The pos tables by prototype and level (`pvc` reads the finest, level 0).
    pub tables: &'a [Vec<Option<PosTable>>],
    /// Build `vcs`, `pvc`.
    pub want: (bool, bool),
    /// Master seed.
    pub seed: u64,
}

/// Builds the tables for the cells the path visits; `render` times one
/// view's draws exactly (RT, picoseconds), `clock` reads it.
pub fn build(
    inp: &Inputs,
    scene: &Scene,
    pvs: &mut Pvs,
    clock: &mut Clock,
    mut render: impl FnMut(&[Draw]) -> Result<f64, SystemError>,
) -> Result<(ViewCellTables, ViewCellSummary), SystemError> {
    let cells = visited(inp.poses, inp.cell);
    let nav = Nav::of(inp.poses);
    let dirs = inp.cfg.directions;
    let lens = Lens::of(inp.cam);
    let mut out = ViewCellTables {
        directions: dirs,
        cell: inp.cell,
        ..Default::default()
    };
    let mut sum = ViewCellSummary {
        directions: dirs,
        cells: cells.len() as u64,
        cells_in_grid: grid_cells(scene, inp.cell),
        samples: inp.cfg.samples,
        vcs_renders: 0,
        vcs_preprocess_seconds: 0.0,
        pvc_bounds: 0,
        pvc_table_reads: 0,
        pvc_preprocess_seconds: 0.0,
    };
    let mut rng = RngStreams::new(inp.seed).stream("estimation.vcs");
    let mut draws = Vec::new();
    for &key in &cells {
        let far = inp.cam.far;
        let eye = [(key.0 as f64 + 0.5) * inp.cell, (key.1 as f64 + 0.5) * inp.cell, 0.0];
        let set: Vec<u32> = pvs.set(scene, inp.cell, eye, far).to_vec();
        if inp.want.0 {
            let t = std::time::Instant::now();
            let mut row = Vec::with_capacity(dirs as usize);
            for bin in 0..dirs as usize {
                let best = max_of_samples(inp.cfg.samples, |_| {
                    let pose = sample_pose(key, inp.cell, bin, dirs, &nav, &mut rng);
                    view_draws(scene, &set, &pose, inp.cam, &mut draws);
                    sum.vcs_renders += 1;
                    Ok(clock.read(render(&draws)?))
                })?;
                row.push(best);
            }
            out.vcs.insert(key, row);
            sum.vcs_preprocess_seconds += t.elapsed().as_secs_f64();
        }
        if inp.want.1 {
            let t = std::time::Instant::now();
            let point_views: Vec<Vec<View>> = if inp.cfg.pvc == PvcReading::Point {
                (0..dirs as usize)
                    .map(|bin| boundary_views(key, inp.cell, bin, dirs, &nav, inp.cam))
                    .collect()
            } else {
                Vec::new()
            };
            let mut row = vec![0.0; dirs as usize];
            for (bin, total) in row.iter_mut().enumerate() {
                for &i in &set {
                    let o = &scene.objects[i as usize];
                    let Some(Some(tb)) = inp.tables[o.proto as usize].first() else {
                        continue;
                    };
                    sum.pvc_bounds += 1;
                    match inp.cfg.pvc {
                        PvcReading::Bound => {
                            if let Some(b) = object_bound(o, key, inp.cell, bin, dirs, &nav, &lens) {
                                *total += tb.lookup_max(b.alpha, b.gamma, b.phi, &mut sum.pvc_table_reads);
                            }
                        }
                        PvcReading::Point => {
                            let views = &point_views[bin];
                            if let Some(p) = largest_point(&views[..], o, &scene.protos[o.proto as usize]) {
                                *total += tb.lookup(p.alpha, p.gamma, p.phi, &mut sum.pvc_table_reads);
                            }
                        }
                    }
                }
            }
            out.pvc.insert(key, row);
            sum.pvc_preprocess_seconds += t.elapsed().as_secs_f64();
        }
    }
    Ok((out, sum))
}

/// Cells of the grid over the scene's objects' extent.
fn grid_cells(scene: &Scene, cell: f64) -> u64 {
    if scene.objects.is_empty() {
        return 0;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for o in &scene.objects {
        for a in 0..2 {
            lo[a] = lo[a].min(o.center[a] - o.radius);
            hi[a] = hi[a].max(o.center[a] + o.radius);
        }
    }
    let n = |a: usize| ((hi[a] / cell).floor() - (lo[a] / cell).floor() + 1.0).max(1.0) as u64;
    n(0).saturating_mul(n(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::systems::walkthrough::scene::Prototype;

    #[test]
    fn vcs_takes_the_largest_sample() {
        let times = [3.0, 9.5, 1.0, 9.4, 0.0];
        let mut calls = 0;
        let m = max_of_samples(times.len() as u32, |i| {
            calls += 1;
            Ok(times[i as usize])
        })
        .unwrap();
        assert_eq!(m, 9.5);
        assert_eq!(calls, 5);
    }

    #[test]
    fn sectors_are_centred_on_their_heading() {
        assert_eq!(bin_of(0.0, 8), 0);
        assert_eq!(bin_of(-0.1, 8), 0);
        assert_eq!(bin_of(TAU / 8.0 * 0.49, 8), 0);
        assert_eq!(bin_of(TAU / 8.0 * 0.51, 8), 1);
        assert_eq!(bin_of(TAU - 0.01, 8), 0);
        assert_eq!(bin_of(3.0, 1), 0);
    }

    /// The paper's reading searches the cell's boundary: every eye on a
    /// face of the cell's box, the sector's centre heading, the middle
    /// pitch; the point it picks is the seeing view of largest α, inside
    /// the bound, and an object behind every view is left out.
    #[test]
    fn the_point_reading_picks_the_largest_view_inside_the_bound() {
        let cam = CameraConfig::default();
        let lens = Lens::of(&cam);
        let nav = Nav {
            z: (1.5, 2.0),
            pitch: (-0.05, 0.1),
        };
        let views = boundary_views((1, 2), 10.0, 2, 8, &nav, &cam);
        assert_eq!(views.len(), 6 * BOUNDARY_GRID * BOUNDARY_GRID);
        let on_face = |e: [f64; 3]| {
            let inside = (10.0..=20.0).contains(&e[0]) && (20.0..=30.0).contains(&e[1]) && (1.5..=2.0).contains(&e[2]);
            let face = [
                e[0] == 10.0,
                e[0] == 20.0,
                e[1] == 20.0,
                e[1] == 30.0,
                e[2] == 1.5,
                e[2] == 2.0,
            ];
            inside && face.iter().any(|&f| f)
        };
        assert!(views.iter().all(|v| on_face(v.eye)));
        let proto = Prototype {
            name: "box".into(),
            size: [6.0, 4.0, 9.0],
            levels: Vec::new(),
            overdraw: 1.0,
            size_sigma: 1.0,
        };
        // Sector 2 of 8 looks along +y: an object ahead is picked, one
        // behind the cell is not.
        let object = |c: [f64; 3]| Object {
            proto: 0,
            center: c,
            radius: proto.radius(),
            yaw: 0.4,
            state: (0, 0, 0),
            block: u32::MAX,
        };
        let ahead = object([16.0, 60.0, 4.5]);
        let p = largest_point(&views, &ahead, &proto).expect("seen ahead");
        let best = views
            .iter()
            .filter(|v| v.sees_sphere(ahead.center, ahead.radius))
            .map(|v| project(v, &ahead, &proto).alpha)
            .fold(0.0f64, f64::max);
        assert_eq!(p.alpha, best);
        let b = object_bound(&ahead, (1, 2), 10.0, 2, 8, &nav, &lens).unwrap();
        assert!(p.disk_pixels <= b.pixels * (1.0 + 1e-9), "{p:?} {b:?}");
        assert!(largest_point(&views, &object([16.0, -40.0, 4.5]), &proto).is_none());
    }

    /// Brute force: views sampled densely in the cell and direction never
    /// show an object larger than its bound, nor from outside its γ and φ
    /// intervals, nor at all when it is left out.
    #[test]
    fn bounds_hold_against_sampled_views() {
        let cam = CameraConfig::default();
        let lens = Lens::of(&cam);
        let proto = Prototype {
            name: "box".into(),
            size: [6.0, 4.0, 9.0],
            levels: Vec::new(),
            overdraw: 1.0,
            size_sigma: 1.0,
        };
        let nav = Nav {
            z: (1.5, 2.0),
            pitch: (-0.05, 0.1),
        };
        let mut rng = RngStreams::new(5).stream("test");
        let mut checked = 0;
        for (k, c) in [
            [14.0, 5.0, 4.5],
            [-8.0, 22.0, 4.5],
            [5.0, 5.0, 4.5],
            [40.0, -30.0, 4.5],
            [12.0, 12.0, 1.0],
            [200.0, 7.0, 4.5],
        ]
        .into_iter()
        .enumerate()
        {
            let o = Object {
                proto: 0,
                center: c,
                radius: proto.radius(),
                yaw: 0.3 * k as f64,
                state: (0, 0, 0),
                block: u32::MAX,
            };
            for bin in 0..8 {
                let b = object_bound(&o, (0, 0), 10.0, bin, 8, &nav, &lens);
                for _ in 0..400 {
                    let pose = sample_pose((0, 0), 10.0, bin, 8, &nav, &mut rng);
                    let view = View::new(&pose, &cam);
                    if !view.sees_sphere(o.center, o.radius) {
                        continue;
                    }
                    let b = b.unwrap_or_else(|| panic!("object {k} left out of bin {bin} but seen from {pose:?}"));
                    let p = project(&view, &o, &proto);
                    assert!(
                        p.disk_pixels <= b.pixels * (1.0 + 1e-9) + 1e-6,
                        "{k} {bin}: {p:?} {b:?}"
                    );
                    let g = if b.gamma.1 - b.gamma.0 >= TAU {
                        true
                    } else {
                        let x = (p.gamma - b.gamma.0).rem_euclid(TAU);
                        x <= b.gamma.1 - b.gamma.0 + 1e-9
                    };
                    assert!(g, "{k} {bin}: gamma {} not in {:?}", p.gamma, b.gamma);
                    assert!(p.phi >= b.phi.0 - 1e-9 && p.phi <= b.phi.1 + 1e-9, "{k} {bin}: phi");
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}
