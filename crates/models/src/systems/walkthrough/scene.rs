//! The walkthrough's scene: objects with a bounding sphere, a position, a
//! rotation, render state and a chain of levels of detail (mesh statistics
//! per level), built from a preset after paper 000 Table 5 and/or listed
//! objects.
//!
//! Table 5 (as read from the garbled text; columns city / terrain / forest):
//! objects 5609 / 1 / 157; triangles 3,453,465 / 86,400 / 579,644;
//! transformed vertices 6,419,303 / 86,000 / 1,028,978 (per triangle 1.86 /
//! 0.99 / 1.78); textures 88 / 1 / 2; state switches 14267 / 1 / 314. The
//! city has a PVS per 10 m view cell on a regular grid (§7.1). Each object
//! here is a box standing on the ground (buildings, tree crowns, the
//! terrain slab); instances of a prototype share its mesh statistics and
//! shape, and differ in position, rotation about the vertical and state.
//! Triangle counts and transformed vertices per triangle vary between
//! prototypes and are scaled so the scene's totals match Table 5 (to
//! rounding, reported in the summary). Transformed vertices are statistics
//! (what a vertex cache achieved on the paper's meshes), not simulated
//! index buffers.

use rand::Rng;

use crate::engine::RngStreams;
use crate::systems::error::{SystemError, invalid};

use super::config::{ObjectConfig, SceneConfig};

/// Names of the presets.
pub const PRESETS: [&str; 3] = ["city", "forest", "terrain"];

/// One level of detail.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Level {
    /// Triangles.
    pub triangles: u64,
    /// Actually transformed vertices (vertex-cache misses).
    pub transformed: u64,
    /// Distinct vertices.
    pub vertices: u64,
}

/// A shape and LOD chain shared by instances.
#[derive(Debug, Clone)]
pub struct Prototype {
    /// Name.
    pub name: String,
    /// Box width (x), depth (y), height (z), metres.
    pub size: [f64; 3],
    /// Levels, finest first.
    pub levels: Vec<Level>,
    /// Surfaces of the object per covered pixel.
    pub overdraw: f64,
    /// Lognormal sigma of its triangles' screen sizes.
    pub size_sigma: f64,
}

impl Prototype {
    /// Radius of the bounding sphere (half the box diagonal).
    pub fn radius(&self) -> f64 {
        0.5 * (self.size[0].powi(2) + self.size[1].powi(2) + self.size[2].powi(2)).sqrt()
    }
}

/// An instance.
#[derive(Debug, Clone, Copy)]
pub struct Object {
    /// Index into [`Scene::protos`].
    pub proto: u32,
    /// Centre of the bounding sphere (the box's centre).
    pub center: [f64; 3],
    /// Radius of the bounding sphere.
    pub radius: f64,
    /// Rotation about the vertical, radians.
    pub yaw: f64,
    /// Shader, texture, material.
    pub state: (u64, u64, u64),
    /// City block holding the object (`u32::MAX`: none).
    pub block: u32,
}

/// How the scene is laid out (what camera paths and PVS use).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Layout {
    /// A grid of `blocks` x `blocks` city blocks of `block` metres with
    /// `street`-metre streets between and around them (street k runs along
    /// [k p, k p + street], p = block + street).
    City {
        /// Blocks per side.
        blocks: u32,
        /// Block side, metres.
        block: f64,
        /// Street width, metres.
        street: f64,
    },
    /// Trees in a square of `side` metres.
    Forest {
        /// Side, metres.
        side: f64,
    },
    /// A terrain slab of `side` metres.
    Terrain {
        /// Side, metres.
        side: f64,
    },
    /// Listed objects only.
    Listed,
}

/// The scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Prototypes.
    pub protos: Vec<Prototype>,
    /// Instances.
    pub objects: Vec<Object>,
    /// Layout.
    pub layout: Layout,
    /// View-cell size, metres (None: no view cells).
    pub view_cell: Option<f64>,
}

/// Scene totals at the finest level (summary `scene`).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SceneTotals {
    /// Objects.
    pub objects: u64,
    /// Prototypes (shared shapes and LOD chains).
    pub prototypes: u64,
    /// Triangles at the finest level.
    pub triangles: u64,
    /// Transformed vertices at the finest level.
    pub transformed_vertices: u64,
    /// Transformed vertices per triangle.
    pub transformed_per_triangle: f64,
    /// Levels of detail per object (largest chain).
    pub lod_levels: u64,
    /// View-cell size, metres (null: none).
    pub view_cell_m: Option<f64>,
}

impl Scene {
    /// Totals at the finest level.
    pub fn totals(&self) -> SceneTotals {
        let (mut t, mut v) = (0u64, 0u64);
        for o in &self.objects {
            let l = &self.protos[o.proto as usize].levels[0];
            t += l.triangles;
            v += l.transformed;
        }
        SceneTotals {
            objects: self.objects.len() as u64,
            prototypes: self.protos.len() as u64,
            triangles: t,
            transformed_vertices: v,
            transformed_per_triangle: if t > 0 { v as f64 / t as f64 } else { 0.0 },
            lod_levels: self.protos.iter().map(|p| p.levels.len() as u64).max().unwrap_or(0),
            view_cell_m: self.view_cell,
        }
    }
}

/// Most objects a walkthrough scene may have (checked before building).
pub const MAX_OBJECTS: u64 = 1 << 20;

fn scaled(n: u64, scale: f64) -> u64 {
    ((n as f64 * scale).round() as u64).max(1)
}

/// A LOD chain: `levels` levels from `triangles`, each `ratio` of the one
/// before (at least one triangle), transformed vertices `acmr` per triangle.
fn chain(triangles: u64, acmr: f64, levels: u32, ratio: f64) -> Vec<Level> {
    (0..levels.max(1))
        .map(|l| {
            let t = ((triangles as f64) * ratio.powi(l as i32)).round().max(1.0) as u64;
            Level {
                triangles: t,
                transformed: (acmr * t as f64).round() as u64,
                vertices: t / 2 + 2,
            }
        })
        .collect()
}

/// Checks the scene keys and builds the scene.
pub fn build_scene(cfg: &SceneConfig, seed: u64) -> Result<Scene, SystemError> {
    if !(cfg.scale.is_finite() && cfg.scale > 0.0 && cfg.scale <= 100.0) {
        return Err(invalid(
            "scene.scale",
            format!("must be > 0 and at most 100, got {}", cfg.scale),
        ));
    }
    if !(1..=16).contains(&cfg.lod_levels) {
        return Err(invalid(
            "scene.lod_levels",
            format!("must be between 1 and 16, got {}", cfg.lod_levels),
        ));
    }
    if !(cfg.lod_ratio.is_finite() && cfg.lod_ratio > 0.0 && cfg.lod_ratio < 1.0) {
        return Err(invalid(
            "scene.lod_ratio",
            format!(
                "must be between 0 and 1 (each level has fewer triangles than the one before), got {}",
                cfg.lod_ratio
            ),
        ));
    }
    if !(cfg.depth_complexity.is_finite() && cfg.depth_complexity >= 1.0) {
        return Err(invalid(
            "scene.depth_complexity",
            format!("must be a number >= 1, got {}", cfg.depth_complexity),
        ));
    }
    if !(cfg.view_cell.is_finite() && cfg.view_cell >= 0.0) {
        return Err(invalid(
            "scene.view_cell",
            format!("must be 0 (none) or a size in metres, got {}", cfg.view_cell),
        ));
    }
    if cfg.objects.len() as u64 > MAX_OBJECTS {
        return Err(invalid(
            "scene.objects",
            format!("{} objects is more than the limit of {MAX_OBJECTS}", cfg.objects.len()),
        ));
    }
    let streams = RngStreams::new(seed);
    let mut scene = match cfg.preset.as_deref() {
        None => Scene {
            protos: Vec::new(),
            objects: Vec::new(),
            layout: Layout::Listed,
            view_cell: None,
        },
        Some(p) => {
            let objects = match p {
                "city" => scaled(5609, cfg.scale),
                "forest" => scaled(157, cfg.scale),
                "terrain" => 1,
                other => {
                    return Err(invalid(
                        "scene.preset",
                        format!("unknown preset {other:?} (known: {})", PRESETS.join(", ")),
                    ));
                }
            };
            if objects > MAX_OBJECTS {
                return Err(invalid(
                    "scene.scale",
                    format!(
                        "preset {p:?} at scale {} has {objects} objects, more than the limit of {MAX_OBJECTS}",
                        cfg.scale
                    ),
                ));
            }
            match p {
                "city" => city(cfg, objects, &streams),
                "forest" => forest(cfg, objects, &streams),
                _ => terrain(cfg),
            }
        }
    };
    for (i, o) in cfg.objects.iter().enumerate() {
        let (proto, object) = listed(o, i)?;
        scene.protos.push(proto);
        scene.objects.push(Object {
            proto: (scene.protos.len() - 1) as u32,
            ..object
        });
    }
    if cfg.preset.is_none() && cfg.view_cell > 0.0 {
        scene.view_cell = Some(cfg.view_cell);
    }
    Ok(scene)
}

fn listed(o: &ObjectConfig, i: usize) -> Result<(Prototype, Object), SystemError> {
    let key = format!("scene.objects.{i}");
    if o.position.iter().any(|v| !v.is_finite()) {
        return Err(invalid(&format!("{key}.position"), "must be three finite numbers"));
    }
    if o.size.iter().any(|v| !(v.is_finite() && *v > 0.0 && *v <= 1e6)) {
        return Err(invalid(
            &format!("{key}.size"),
            format!("must be three sizes > 0 and at most 1e6 metres, got {:?}", o.size),
        ));
    }
    if !o.yaw.is_finite() {
        return Err(invalid(&format!("{key}.yaw"), "must be a finite angle in degrees"));
    }
    if o.levels.is_empty() {
        return Err(invalid(&format!("{key}.levels"), "needs at least one level of detail"));
    }
    if o.levels.len() > 16 {
        return Err(invalid(&format!("{key}.levels"), "at most 16 levels of detail"));
    }
    let mut levels = Vec::new();
    for (l, lc) in o.levels.iter().enumerate() {
        let lk = format!("{key}.levels.{l}");
        if lc.triangles == 0 || lc.triangles > crate::limits::MAX_MESH_INDICES / 3 {
            return Err(invalid(
                &format!("{lk}.triangles"),
                format!(
                    "must be between 1 and {}, got {}",
                    crate::limits::MAX_MESH_INDICES / 3,
                    lc.triangles
                ),
            ));
        }
        if !(lc.acmr.is_finite() && (0.0..=3.0).contains(&lc.acmr)) {
            return Err(invalid(
                &format!("{lk}.acmr"),
                format!("must be between 0 and 3, got {}", lc.acmr),
            ));
        }
        if let Some(prev) = levels.last().map(|p: &Level| p.triangles)
            && lc.triangles >= prev
        {
            return Err(invalid(
                &format!("{lk}.triangles"),
                format!(
                    "levels must get coarser: {} triangles is not fewer than the level before ({prev})",
                    lc.triangles
                ),
            ));
        }
        levels.push(Level {
            triangles: lc.triangles,
            transformed: (lc.acmr * lc.triangles as f64).round() as u64,
            vertices: lc.vertices.unwrap_or(lc.triangles / 2 + 2),
        });
    }
    if !(o.overdraw.is_finite() && o.overdraw > 0.0 && o.overdraw <= 1000.0) {
        return Err(invalid(
            &format!("{key}.overdraw"),
            format!("must be > 0 and at most 1000, got {}", o.overdraw),
        ));
    }
    if !(o.size_sigma.is_finite() && (0.0..=5.0).contains(&o.size_sigma)) {
        return Err(invalid(
            &format!("{key}.size_sigma"),
            format!("must be between 0 and 5, got {}", o.size_sigma),
        ));
    }
    let proto = Prototype {
        name: o.name.clone(),
        size: o.size,
        levels,
        overdraw: o.overdraw,
        size_sigma: o.size_sigma,
    };
    let object = Object {
        proto: 0,
        center: [o.position[0], o.position[1], o.position[2] + 0.5 * o.size[2]],
        radius: proto.radius(),
        yaw: o.yaw.to_radians(),
        state: (o.shader, o.texture, o.material),
        block: u32::MAX,
    };
    Ok((proto, object))
}

/// Scales the prototypes' finest triangle counts so that the instances add
/// up to `target` triangles, and their transformed vertices per triangle
/// (`acmr`, each prototype's own: vertex-cache efficiency differs between
/// meshes) so that they add up to `target_tv` (both to rounding), then
/// builds their chains.
fn scale_to_total(
    raw: &[f64],
    acmr: &[f64],
    counts: &[u64],
    target: f64,
    target_tv: f64,
    cfg: &SceneConfig,
) -> Vec<Vec<Level>> {
    let total: f64 = raw.iter().zip(counts).map(|(t, c)| t * *c as f64).sum();
    let k = if total > 0.0 { target / total } else { 1.0 };
    let tris: Vec<u64> = raw.iter().map(|t| (t * k).round().max(1.0) as u64).collect();
    let tv: f64 = tris
        .iter()
        .zip(acmr)
        .zip(counts)
        .map(|((t, a), c)| *t as f64 * a * *c as f64)
        .sum();
    let ka = if tv > 0.0 { target_tv / tv } else { 1.0 };
    tris.iter()
        .zip(acmr)
        .map(|(t, a)| chain(*t, (a * ka).clamp(0.0, 3.0), cfg.lod_levels, cfg.lod_ratio))
        .collect()
}

/// City blocks of 60 m, streets of 20 m, four buildings per block (one per
/// quadrant, each facing two streets), 32 building prototypes, 88 textures,
/// 3 materials, PVS per 10 m view cell.
fn city(cfg: &SceneConfig, n: u64, streams: &RngStreams) -> Scene {
    const PROTOS: usize = 32;
    let (block, street) = (60.0, 20.0);
    let pitch = block + street;
    let blocks = ((n as f64 / 4.0).sqrt().ceil() as u32).max(1);
    let mut rng = streams.stream("scene.city.prototypes");
    let mut sizes = Vec::new();
    let mut raw = Vec::new();
    let mut acmr = Vec::new();
    for _ in 0..PROTOS {
        acmr.push(rng.random_range(0.6..1.4));
        let w = rng.random_range(16.0..26.0);
        let d = rng.random_range(16.0..26.0);
        let h = 8.0 * (rng.random_range(0.0f64..1.0) * (40.0f64 / 8.0).ln()).exp();
        sizes.push([w, d, h]);
        raw.push(616.0 * rng.random_range(0.5..1.5));
    }
    let mut rng = streams.stream("scene.city.objects");
    let mut objects = Vec::with_capacity(n as usize);
    let mut counts = vec![0u64; PROTOS];
    for k in 0..n {
        let b = (k / 4) as u32;
        let q = k % 4;
        let (bi, bj) = (b % blocks, b / blocks);
        let x = street + bi as f64 * pitch + 15.0 + 30.0 * (q % 2) as f64;
        let y = street + bj as f64 * pitch + 15.0 + 30.0 * (q / 2) as f64;
        let p = rng.random_range(0..PROTOS);
        counts[p] += 1;
        let yaw = (rng.random_range(0..4u32) as f64) * std::f64::consts::FRAC_PI_2;
        let state = (0, rng.random_range(0..88u64), rng.random_range(0..3u64));
        objects.push(Object {
            proto: p as u32,
            center: [x, y, 0.5 * sizes[p][2]],
            radius: 0.0,
            yaw,
            state,
            block: b,
        });
    }
    let chains = scale_to_total(
        &raw,
        &acmr,
        &counts,
        3_453_465.0 * cfg.scale,
        6_419_303.0 * cfg.scale,
        cfg,
    );
    let protos = prototypes(chains, &sizes, "building", 1.0, 1.5, &mut objects);
    Scene {
        protos,
        objects,
        layout: Layout::City { blocks, block, street },
        view_cell: Some(10.0),
    }
}

/// The prototypes `<kind>-<i>` of `chains` (LOD levels) and `sizes`, and
/// each object's bounding radius from its prototype.
fn prototypes(
    chains: Vec<Vec<Level>>,
    sizes: &[[f64; 3]],
    kind: &str,
    overdraw: f64,
    size_sigma: f64,
    objects: &mut [Object],
) -> Vec<Prototype> {
    let protos: Vec<Prototype> = chains
        .into_iter()
        .zip(sizes)
        .enumerate()
        .map(|(i, (levels, size))| Prototype {
            name: format!("{kind}-{i}"),
            size: *size,
            levels,
            overdraw,
            size_sigma,
        })
        .collect();
    for o in objects {
        o.radius = protos[o.proto as usize].radius();
    }
    protos
}

/// Trees (crowns as boxes) scattered over a square at about 16 m spacing,
/// 16 tree prototypes, 2 textures (bark and leaves alternate), leaves
/// overlapping (overdraw 2.5) and strongly varying triangle sizes.
fn forest(cfg: &SceneConfig, n: u64, streams: &RngStreams) -> Scene {
    const PROTOS: usize = 16;
    let side = 16.0 * (n as f64).sqrt();
    let mut rng = streams.stream("scene.forest.prototypes");
    let mut sizes = Vec::new();
    let mut raw = Vec::new();
    let mut acmr = Vec::new();
    for _ in 0..PROTOS {
        acmr.push(rng.random_range(0.6..1.4));
        let w = rng.random_range(4.0..10.0);
        let h = rng.random_range(8.0..20.0);
        sizes.push([w, w * rng.random_range(0.8..1.2), h]);
        raw.push(3692.0 * rng.random_range(0.6..1.4));
    }
    let mut rng = streams.stream("scene.forest.objects");
    let mut objects: Vec<Object> = Vec::with_capacity(n as usize);
    let mut counts = vec![0u64; PROTOS];
    for k in 0..n {
        // Rejection sampling for a 6 m spacing, with a bounded number of tries.
        let mut pos = [0.0, 0.0];
        for _ in 0..64 {
            pos = [rng.random_range(0.0..side), rng.random_range(0.0..side)];
            if objects
                .iter()
                .all(|o| (o.center[0] - pos[0]).powi(2) + (o.center[1] - pos[1]).powi(2) >= 36.0)
            {
                break;
            }
        }
        let p = rng.random_range(0..PROTOS);
        counts[p] += 1;
        objects.push(Object {
            proto: p as u32,
            center: [pos[0], pos[1], 0.5 * sizes[p][2]],
            radius: 0.0,
            yaw: rng.random_range(0.0..std::f64::consts::TAU),
            state: (0, k % 2, rng.random_range(0..2u64)),
            block: u32::MAX,
        });
    }
    let chains = scale_to_total(
        &raw,
        &acmr,
        &counts,
        579_644.0 * cfg.scale,
        1_028_978.0 * cfg.scale,
        cfg,
    );
    let protos = prototypes(chains, &sizes, "tree", 2.5, 2.0, &mut objects);
    Scene {
        protos,
        objects,
        layout: Layout::Forest { side },
        view_cell: None,
    }
}

/// One terrain slab of 3 km x 3 km x 60 m, 86,400 triangles at scale 1,
/// 0.99 transformed vertices per triangle (strips adapted to the cache).
fn terrain(cfg: &SceneConfig) -> Scene {
    let side = 3000.0;
    let proto = Prototype {
        name: "terrain".into(),
        size: [side, side, 60.0],
        levels: chain(scaled(86_400, cfg.scale), 0.99, cfg.lod_levels, cfg.lod_ratio),
        overdraw: 1.0,
        size_sigma: 0.8,
    };
    let radius = proto.radius();
    Scene {
        protos: vec![proto],
        objects: vec![Object {
            proto: 0,
            center: [0.5 * side, 0.5 * side, 30.0],
            radius,
            yaw: 0.0,
            state: (0, 0, 0),
            block: u32::MAX,
        }],
        layout: Layout::Terrain { side },
        view_cell: None,
    }
}
