//! Compiles a model's workload into what the simulation consumes: the list
//! of draws in submission order with their CPU and GPU front-end costs, the
//! meshes' per-triangle transformed-vertex counts, and per-group fragment
//! costs. Only what the scene uses is built: no vertex-cache simulation for
//! non-indexed draws or at `draw` fidelity beyond the totals, no upload work
//! for scenes without uploads.

use std::collections::HashMap;
use std::path::Path;

use crate::components::distribution::Dist;
use crate::components::vertex_cache::CachePolicy;
use crate::engine::Duration;
use crate::scene::config::{DepthOrder, GeometryMemory, MeshRef, SceneWorkload, SizeOrder, StateOrder};
use crate::scene::generators::mesh_from_spec;
use crate::scene::states::{StateNumbering, group_states_error, scene_groups};

use super::closed_form::{DrawTimes, draw_times, draw_times_unified, ordered_draw_total};
use super::config::{Fidelity, FramePipelineConfig};
use super::geometry_cost::{CostOverflow, geometry_cost};

/// Errors while building the workload.
#[derive(Debug, thiserror::Error)]
pub enum WorkloadError {
    /// A key has a value the simulator cannot use.
    #[error("{key}: {message}")]
    Invalid {
        /// Dotted key path.
        key: String,
        /// What is wrong.
        message: String,
    },
}

impl From<WorkloadError> for crate::systems::error::SystemError {
    /// A scene that cannot be compiled is a model value the system cannot
    /// use, blamed on its key.
    fn from(e: WorkloadError) -> Self {
        match e {
            WorkloadError::Invalid { key, message } => Self::Invalid { key, message },
        }
    }
}

fn invalid(key: impl Into<String>, message: impl Into<String>) -> WorkloadError {
    WorkloadError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}

/// How many vertices each triangle of a mesh transforms.
#[derive(Debug, Clone)]
pub enum Misses {
    /// Simulated through the vertex cache, one count per triangle.
    PerTriangle(Vec<u8>),
    /// Statistics only: `transformed` spread evenly over the triangles
    /// (error diffusion, so every prefix is as even as possible).
    Spread {
        /// Total transformed vertices.
        transformed: u64,
    },
    /// The same count for every triangle (non-indexed: 3; no cache: 3).
    Constant(u8),
}

impl Misses {
    /// Transformed vertices of triangle `t` out of `n`.
    #[inline]
    pub fn of(&self, t: u64, n: u64) -> u64 {
        match self {
            Misses::PerTriangle(v) => v[t as usize] as u64,
            Misses::Spread { transformed } => {
                let a = (t as u128 * *transformed as u128) / n as u128;
                let b = ((t + 1) as u128 * *transformed as u128) / n as u128;
                (b - a) as u64
            }
            Misses::Constant(c) => *c as u64,
        }
    }
}

/// A mesh as the geometry stage sees it.
#[derive(Debug, Clone)]
pub struct MeshInfo {
    /// Name or spec.
    pub name: String,
    /// Triangles.
    pub triangles: u64,
    /// Actually transformed vertices.
    pub transformed: u64,
    /// Indices fetched (0 for non-indexed draws).
    pub indices: u64,
    /// Per-triangle transformed counts (only built at `triangle` fidelity).
    pub misses: Misses,
    /// Geometry-stage time of one draw of the mesh.
    pub geometry_time: Duration,
    /// The vertex-shader part of `geometry_time` (the rest is index fetch
    /// and triangle setup, fixed function on a unified GPU).
    pub geometry_shader: Duration,
}

/// A group's fragment-stage parameters.
#[derive(Debug, Clone)]
pub struct GroupInfo {
    /// Name.
    pub name: String,
    /// Screen-space triangle area, pixels.
    pub pixels: Dist<f64>,
    /// Order of the sizes within a draw.
    pub order: SizeOrder,
    /// Unified: expected shader work per covered pixel (on the pool), ps.
    pub shade_per_pixel: f64,
    /// Unified: expected fixed-function time per covered pixel (depth test
    /// of rejected fragments, rasterization and blending of shaded ones), ps.
    pub fixed_per_pixel: f64,
    /// Where the group's vertices live (and so where its uploads go).
    pub memory: GeometryMemory,
    /// Bytes fetched over the bus per transformed vertex (0 in video memory).
    pub fetch_bytes_per_vertex: f64,
    /// Whether the CPU sorts the group's draws into place every frame
    /// (`changes.sorted_each_frame`: each pays `cpu.sort_per_draw`).
    pub sorted_each_frame: bool,
}

impl GroupInfo {
    /// Expected fragment cost per covered pixel, picoseconds (early-z folded
    /// in): the split fragment stage's time per pixel, shader and
    /// fixed-function parts one after the other.
    pub fn cost_per_pixel(&self) -> f64 {
        self.shade_per_pixel + self.fixed_per_pixel
    }
}

/// One draw call with the commands that precede it.
#[derive(Debug, Clone)]
pub struct DrawItem {
    /// Index into [`SceneProgram::groups`].
    pub group: u32,
    /// Index into [`SceneProgram::meshes`].
    pub mesh: u32,
    /// CPU time before the batch is pushed (traversal, driver, uploads).
    pub cpu: Duration,
    /// GPU front-end time for the batch.
    pub front: Duration,
    /// GPU front-end time for its state changes that waits for the
    /// geometry stage to finish the draw before (`gpu.state_change_stalls`;
    /// zero otherwise, the changes being inside `front`).
    pub setup: Duration,
    /// Commands in the batch (state changes + upload + draw).
    pub commands: u32,
    /// Bytes of the batch.
    pub bytes: u64,
    /// The draw's closed-form times (computed at `draw` fidelity only).
    pub closed: Option<DrawTimes>,
    /// Bytes the CPU copies for the draw (geometry and texture uploads).
    pub upload: u64,
    /// The copy's time alone, at its memory's rate (`bus.bandwidth` into
    /// AGP memory, `bus.video_copy` into video memory); inside `cpu` unless
    /// the scene shares its bus ([`SceneProgram::bus_shared`]).
    pub copy: Duration,
}

/// Scene statistics per frame, reported in the summary.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SceneStats {
    /// Objects drawn.
    pub objects: u64,
    /// Triangles.
    pub triangles: u64,
    /// Actually transformed vertices.
    pub transformed_vertices: u64,
    /// Shader changes.
    pub shader_changes: u64,
    /// Texture changes.
    pub texture_changes: u64,
    /// Material changes.
    pub material_changes: u64,
    /// Matrix changes.
    pub matrix_changes: u64,
    /// Blending (alpha) state changes (only groups with `changes.alpha`
    /// have them).
    #[serde(skip_serializing_if = "is_zero")]
    pub alpha_changes: u64,
    /// Bytes uploaded over the bus.
    pub upload_bytes: u64,
    /// Bytes of vertices fetched from AGP memory over the bus.
    #[serde(skip_serializing_if = "is_zero")]
    pub agp_fetch_bytes: u64,
    /// Probability that a fragment passes early-z.
    pub early_z_pass: f64,
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

/// A compiled scene.
#[derive(Debug, Clone)]
pub struct SceneProgram {
    /// Draws in submission order.
    pub draws: Vec<DrawItem>,
    /// Meshes.
    pub meshes: Vec<MeshInfo>,
    /// Groups.
    pub groups: Vec<GroupInfo>,
    /// Per-frame statistics.
    pub stats: SceneStats,
    /// Whether copies and vertex fetch can meet on the bus (some group's
    /// vertices are in AGP memory and some draw uploads): then a draw's copy
    /// is a step of its own on the CPU thread, at the rate the bus gives it
    /// ([`crate::components::shared_bus`]), and not inside its `cpu` time.
    pub bus_shared: bool,
}

/// One object instance before ordering: its group, mesh, state ids
/// (shader, texture, material), own matrix, and upload bytes per frame.
#[derive(Debug, Clone, Copy)]
pub struct Instance {
    /// Index into the program's groups.
    pub group: u32,
    /// Index into the program's meshes.
    pub mesh: u32,
    /// Shader, texture and material ids.
    pub state: (u64, u64, u64),
    /// Whether the instance sets its own matrix.
    pub matrix: bool,
    /// Blending (alpha) state id (0: opaque).
    pub alpha: u64,
    /// Upload bytes per frame.
    pub upload: u64,
}

/// Probability that a fragment is shaded (passes early-z) given the depth
/// complexity `d` and the draw order: front-to-back 1/d, back-to-front 1,
/// random H(d)/d (the k-th of d surfaces drawn in random order is the nearest
/// so far with probability 1/k; H is the harmonic number, extended to real d
/// by H(d) = digamma(d+1) + Euler's gamma).
pub fn early_z_pass(order: DepthOrder, d: f64) -> f64 {
    match order {
        DepthOrder::FrontToBack => 1.0 / d,
        DepthOrder::BackToFront => 1.0,
        DepthOrder::Random => {
            let h = statrs::function::gamma::digamma(d + 1.0) + 0.577_215_664_901_532_9;
            (h / d).clamp(0.0, 1.0)
        }
    }
}

fn mul(d: Duration, n: u64, key: &str) -> Result<Duration, WorkloadError> {
    d.checked_mul(n)
        .ok_or_else(|| invalid(key, "cost x count overflows the 64-bit picosecond range"))
}
fn add(a: Duration, b: Duration, key: &str) -> Result<Duration, WorkloadError> {
    a.checked_add(b)
        .ok_or_else(|| invalid(key, "sum of costs overflows the 64-bit picosecond range"))
}

/// What a draw's closed-form times depend on besides the draw: the triangle
/// FIFO's depth, whether the shaders are one unified pool, and the seed of
/// the sorted sizes' sample.
#[derive(Debug, Clone, Copy)]
pub struct ClosedForm {
    depth: Option<u32>,
    unified: bool,
    seed: u64,
}

impl ClosedForm {
    /// The closed form's terms of `cfg`.
    pub fn of(cfg: &FramePipelineConfig) -> Self {
        ClosedForm {
            depth: cfg.gpu.fragment.depth(),
            unified: cfg.gpu.pool().is_some(),
            seed: cfg.run.seed,
        }
    }

    /// Whether the shaders are one unified pool.
    pub fn unified(&self) -> bool {
        self.unified
    }
}

/// The closed-form times of one draw of mesh `m` in group `g` (the `draw`
/// fidelity), for the model's architecture (`form`).
pub fn closed_times(form: &ClosedForm, m: &MeshInfo, g: &GroupInfo) -> DrawTimes {
    let depth = form.depth;
    if g.order != SizeOrder::Random {
        return ordered_closed_times(form, m, g);
    }
    if !form.unified {
        return draw_times(m.triangles, m.geometry_time, &g.pixels, g.cost_per_pixel(), depth);
    }
    draw_times_unified(
        m.triangles,
        m.geometry_shader,
        m.geometry_time.saturating_sub(m.geometry_shader),
        &g.pixels,
        g.shade_per_pixel,
        g.fixed_per_pixel,
        depth,
    )
}

/// Triangles a draw may have when its sizes are sorted (`size_order`): the
/// sizes are held in memory for the draw (8 bytes each).
pub const MAX_ORDERED_TRIANGLES: u64 = 1 << 24;

/// The sorted sizes of one draw of `n` triangles from `g`'s distribution.
pub fn ordered_sizes(g: &GroupInfo, n: u64, rng: &mut crate::engine::StreamRng, out: &mut Vec<f64>) {
    out.clear();
    out.extend((0..n).map(|_| g.pixels.sample(rng)));
    out.sort_by(f64::total_cmp);
    if g.order == SizeOrder::Descending {
        out.reverse();
    }
}

/// [`closed_times`] for sorted sizes: one sample of the draw's sizes (its
/// own stream, so the same for every draw of the mesh), pushed through the
/// exact pipeline recursion ([`ordered_draw_total`]); on the unified pool
/// at least the draw's shader work.
fn ordered_closed_times(form: &ClosedForm, m: &MeshInfo, g: &GroupInfo) -> DrawTimes {
    let n = m.triangles;
    let mut rng = crate::engine::RngStreams::new(form.seed).stream("fragment.pixels.ordered");
    let mut sizes = Vec::new();
    ordered_sizes(g, n, &mut rng, &mut sizes);
    let unified = form.unified;
    let g_fixed = m.geometry_time.saturating_sub(m.geometry_shader);
    let per_triangle = if unified {
        m.geometry_shader.max(g_fixed).0 as f64 / n.max(1) as f64
    } else {
        m.geometry_time.0 as f64 / n.max(1) as f64
    };
    let per_pixel = if unified {
        g.shade_per_pixel.max(g.fixed_per_pixel)
    } else {
        g.cost_per_pixel()
    };
    let fragment: Vec<f64> = sizes.iter().map(|px| px * per_pixel).collect();
    let mut total = ordered_draw_total(per_triangle, &fragment, form.depth);
    if unified {
        let shader = m.geometry_shader.0 as f64 + sizes.iter().sum::<f64>() * g.shade_per_pixel;
        total = total.max(shader);
    }
    let geometry = Duration::from_ps_f64(per_triangle * n as f64);
    let fragment = Duration::from_ps_f64(fragment.iter().sum());
    DrawTimes {
        geometry,
        fragment,
        total: Duration::from_ps_f64(total).max(geometry).max(fragment),
    }
}

/// Compiles the scene workload of `cfg`.
pub fn compile_scene(
    cfg: &FramePipelineConfig,
    scene: &SceneWorkload,
    base_dir: &Path,
) -> Result<SceneProgram, WorkloadError> {
    if !(scene.depth_complexity.is_finite() && scene.depth_complexity >= 1.0) {
        return Err(invalid(
            "workload.depth_complexity",
            format!("must be a number >= 1, got {}", scene.depth_complexity),
        ));
    }
    if !(scene.scale.is_finite() && scene.scale > 0.0) {
        return Err(invalid(
            "workload.scale",
            format!("must be a number > 0, got {}", scene.scale),
        ));
    }
    let groups_cfg = scene_groups(scene).map_err(|e| invalid("workload.preset", e.to_string()))?;

    let pass = early_z_pass(scene.depth_order, scene.depth_complexity);
    let (shade_per_pixel, fixed_per_pixel) = fragment_costs(cfg, pass);
    let geo = &cfg.gpu.geometry;
    let need_per_triangle = cfg.fidelity == Fidelity::Triangle;

    let mut meshes: Vec<MeshInfo> = Vec::new();
    let mut mesh_ids: HashMap<(String, bool), u32> = HashMap::new();
    let mut groups = Vec::new();
    let mut objects: Vec<Instance> = Vec::new();
    let mut numbering = StateNumbering::default();

    for (gi, g) in groups_cfg.iter().enumerate() {
        let key = if gi >= groups_cfg.len() - scene.groups.len() {
            format!("workload.groups.{}", gi - (groups_cfg.len() - scene.groups.len()))
        } else {
            format!("workload.preset ({})", g.name)
        };
        g.triangle_pixels
            .validate()
            .map_err(|e| invalid(format!("{key}.triangle_pixels"), e.to_string()))?;
        if let Some((what, message)) = group_states_error(g) {
            return Err(invalid(format!("{key}.{what}"), message));
        }
        let mesh_key = (format!("{:?}", g.mesh), g.indexed);
        let mesh_id = match mesh_ids.get(&mesh_key) {
            Some(&id) => id,
            None => {
                let info = build_mesh(&g.mesh, g.indexed, &geo.vertex_cache, need_per_triangle, base_dir, &key)?;
                meshes.push(timed_mesh(cfg, info, &key)?);
                let id = (meshes.len() - 1) as u32;
                mesh_ids.insert(mesh_key, id);
                id
            }
        };
        if g.size_order != SizeOrder::Random && meshes[mesh_id as usize].triangles > MAX_ORDERED_TRIANGLES {
            return Err(invalid(
                format!("{key}.size_order"),
                format!(
                    "sorting a draw's sizes holds them in memory: at most {MAX_ORDERED_TRIANGLES} triangles per draw, the mesh has {}",
                    meshes[mesh_id as usize].triangles
                ),
            ));
        }
        if g.geometry_memory == GeometryMemory::Agp && g.vertex_bytes.0 == 0 {
            return Err(invalid(
                format!("{key}.vertex_bytes"),
                "must be at least 1 byte when geometry_memory = \"agp\" (the bytes fetched over the bus per transformed vertex)",
            ));
        }
        groups.push(GroupInfo {
            name: g.name.clone(),
            pixels: g.triangle_pixels.clone(),
            shade_per_pixel,
            fixed_per_pixel,
            order: g.size_order,
            memory: g.geometry_memory,
            fetch_bytes_per_vertex: match g.geometry_memory {
                GeometryMemory::Agp => g.vertex_bytes.0 as f64,
                GeometryMemory::Video => 0.0,
            },
            sorted_each_frame: g.changes.as_ref().is_some_and(|c| c.sorted_each_frame),
        });
        for i in 0..g.count {
            objects.push(Instance {
                group: gi as u32,
                mesh: mesh_id,
                state: numbering.state(g, i),
                matrix: StateNumbering::sets_matrix(g, i),
                alpha: numbering.alpha(g, i),
                upload: g.geometry_upload.0.saturating_add(g.texture_upload.0),
            });
        }
        numbering.next_group(g);
    }
    if scene.state_order == StateOrder::Sorted {
        objects.sort_by_key(|o| o.state);
    }

    build_program(cfg, meshes, groups, &objects, pass)
}

/// The fragment costs per covered pixel for an early-z pass probability
/// `pass`: (shader work, fixed-function time), picoseconds (see
/// [`GroupInfo`]).
pub fn fragment_costs(cfg: &FramePipelineConfig, pass: f64) -> (f64, f64) {
    let frag = &cfg.gpu.fragment;
    let shade_per_pixel = pass * frag.per_fragment.0 as f64;
    let fixed_per_pixel = pass * frag.fixed_per_fragment.0 as f64 + (1.0 - pass) * frag.per_rejected_fragment.0 as f64;
    (shade_per_pixel, fixed_per_pixel)
}

/// `info` with its geometry-stage times from the model's costs (index
/// fetch, vertex shader per transformed vertex, triangle setup); `key`
/// names the mesh in errors.
pub fn timed_mesh(cfg: &FramePipelineConfig, info: MeshInfo, key: &str) -> Result<MeshInfo, WorkloadError> {
    let cost =
        geometry_cost(&cfg.gpu.geometry, info.transformed, info.indices, info.triangles).map_err(|e| match e {
            CostOverflow::Product => invalid(key, "cost x count overflows the 64-bit picosecond range"),
            CostOverflow::Sum => invalid(key, "sum of costs overflows the 64-bit picosecond range"),
        })?;
    Ok(MeshInfo {
        geometry_time: cost.total,
        geometry_shader: cost.shader,
        ..info
    })
}

/// The draws of `objects` in the order given, with their CPU and GPU
/// front-end costs (state changes against the previous draw, uploads, the
/// draw command) and, at `draw` fidelity, their closed-form times; `pass` is
/// the early-z pass probability reported in the statistics. Used by
/// [`compile_scene`] and by systems that build a frame's objects themselves
/// (the walkthrough).
pub fn build_program(
    cfg: &FramePipelineConfig,
    meshes: Vec<MeshInfo>,
    groups: Vec<GroupInfo>,
    objects: &[Instance],
    pass: f64,
) -> Result<SceneProgram, WorkloadError> {
    let cpu = &cfg.cpu;
    let gpu = &cfg.gpu;
    let bytes = &cfg.command_fifo.bytes;
    let mut stats = SceneStats {
        early_z_pass: pass,
        ..Default::default()
    };
    let mut draws = Vec::with_capacity(objects.len());
    let mut prev: Option<(u64, u64, u64)> = None;
    let mut prev_alpha = 0;
    let bus_shared = objects.iter().any(|o| o.upload > 0)
        && objects
            .iter()
            .any(|o| groups[o.group as usize].fetch_bytes_per_vertex > 0.0);
    // Closed forms per (mesh, group): computed once, only at `draw` fidelity.
    let mut closed_cache: HashMap<(u32, u32), DrawTimes> = HashMap::new();
    let form = ClosedForm::of(cfg);
    for o in objects {
        let Instance {
            group,
            mesh,
            state: (sh, tx, mt),
            matrix,
            alpha,
            upload: up,
        } = *o;
        let changed = [
            prev.is_none_or(|p| p.0 != sh),
            prev.is_none_or(|p| p.1 != tx),
            prev.is_none_or(|p| p.2 != mt),
            matrix,
            alpha != prev_alpha,
        ];
        prev = Some((sh, tx, mt));
        prev_alpha = alpha;
        let cpu_costs = [
            cpu.state_change.shader,
            cpu.state_change.texture,
            cpu.state_change.material,
            cpu.state_change.matrix,
            cpu.state_change.alpha,
        ];
        let gpu_costs = [
            gpu.state_change.shader,
            gpu.state_change.texture,
            gpu.state_change.material,
            gpu.state_change.matrix,
            gpu.state_change.alpha,
        ];
        let mut c = add(cpu.per_object, cpu.per_draw, "cpu")?;
        if groups[group as usize].sorted_each_frame {
            c = add(c, cpu.sort_per_draw, "cpu.sort_per_draw")?;
        }
        // The GPU's state changes: on the front end beside the draw before,
        // or (stalling) once the geometry stage is free.
        let mut states = Duration::ZERO;
        let mut commands = 1u32;
        let mut b = bytes.draw.0;
        for k in 0..changed.len() {
            if changed[k] {
                c = add(c, cpu_costs[k], "cpu.state_change")?;
                states = add(states, gpu_costs[k], "gpu.state_change")?;
                commands += 1;
                b += bytes.state.0;
            }
        }
        stats.shader_changes += changed[0] as u64;
        stats.texture_changes += changed[1] as u64;
        stats.material_changes += changed[2] as u64;
        stats.matrix_changes += changed[3] as u64;
        stats.alpha_changes += changed[4] as u64;
        let mut copy = Duration::ZERO;
        if up > 0 {
            copy = cfg.bus.copy_bandwidth(groups[group as usize].memory).transfer_time(up);
            if !bus_shared {
                c = add(c, copy, "bus.bandwidth")?;
            }
            commands += 1;
            b += bytes.upload.0;
            stats.upload_bytes += up;
        }
        let (f, setup) = if gpu.state_change_stalls {
            (Duration::ZERO, states)
        } else {
            (states, Duration::ZERO)
        };
        let f = add(f, mul(gpu.command, commands as u64, "gpu.command")?, "gpu.command")?;
        let m = &meshes[mesh as usize];
        stats.objects += 1;
        stats.triangles += m.triangles;
        stats.transformed_vertices += m.transformed;
        let fetch = groups[group as usize].fetch_bytes_per_vertex;
        stats.agp_fetch_bytes += (m.transformed as f64 * fetch).round() as u64;
        // A draw fetching from AGP memory takes its closed form when it
        // starts, at the bus's share then.
        let closed = (cfg.fidelity == Fidelity::Draw && fetch == 0.0).then(|| {
            *closed_cache
                .entry((mesh, group))
                .or_insert_with(|| closed_times(&form, m, &groups[group as usize]))
        });
        draws.push(DrawItem {
            group,
            mesh,
            cpu: c,
            front: f,
            setup,
            commands,
            bytes: b,
            closed,
            upload: up,
            copy,
        });
    }
    Ok(SceneProgram {
        draws,
        meshes,
        groups,
        stats,
        bus_shared,
    })
}

fn build_mesh(
    mesh: &MeshRef,
    indexed: bool,
    policy: &CachePolicy,
    per_triangle: bool,
    base_dir: &Path,
    key: &str,
) -> Result<MeshInfo, WorkloadError> {
    match mesh {
        MeshRef::Stats { triangles, acmr } => {
            if !(acmr.is_finite() && (0.0..=3.0).contains(acmr)) {
                return Err(invalid(
                    format!("{key}.mesh.acmr"),
                    format!("must be between 0 and 3, got {acmr}"),
                ));
            }
            let (transformed, misses) = if indexed {
                let tv = (*acmr * *triangles as f64).round() as u64;
                (tv, Misses::Spread { transformed: tv })
            } else {
                (triangles.saturating_mul(3), Misses::Constant(3))
            };
            Ok(MeshInfo {
                name: format!("{triangles} triangles, acmr {acmr}"),
                triangles: *triangles,
                transformed,
                indices: if indexed { triangles.saturating_mul(3) } else { 0 },
                misses,
                geometry_time: Duration::ZERO,
                geometry_shader: Duration::ZERO,
            })
        }
        MeshRef::Spec(spec) => {
            let m = mesh_from_spec(spec, base_dir).map_err(|e| invalid(format!("{key}.mesh"), e.to_string()))?;
            let triangles = m.triangles();
            if !indexed || *policy == CachePolicy::None {
                return Ok(MeshInfo {
                    name: spec.clone(),
                    triangles,
                    transformed: triangles * 3,
                    indices: if indexed {
                        m.cache_stats(&CachePolicy::None).indices
                    } else {
                        0
                    },
                    misses: Misses::Constant(3),
                    geometry_time: Duration::ZERO,
                    geometry_shader: Duration::ZERO,
                });
            }
            let (transformed, misses, indices) = if per_triangle {
                let v = m.misses_per_triangle(policy);
                let tv = v.iter().map(|&x| x as u64).sum();
                let idx = m.cache_stats(&CachePolicy::None).indices;
                (tv, Misses::PerTriangle(v), idx)
            } else {
                let s = m.cache_stats(policy);
                (
                    s.transformed,
                    Misses::Spread {
                        transformed: s.transformed,
                    },
                    s.indices,
                )
            };
            Ok(MeshInfo {
                name: spec.clone(),
                triangles,
                transformed,
                indices,
                misses,
                geometry_time: Duration::ZERO,
                geometry_shader: Duration::ZERO,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn early_z_orders() {
        assert_eq!(early_z_pass(DepthOrder::FrontToBack, 4.0), 0.25);
        assert_eq!(early_z_pass(DepthOrder::BackToFront, 4.0), 1.0);
        let r = early_z_pass(DepthOrder::Random, 4.0);
        assert!((r - (1.0 + 0.5 + 1.0 / 3.0 + 0.25) / 4.0).abs() < 1e-9, "{r}");
        assert!((early_z_pass(DepthOrder::Random, 1.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn spread_misses_sum_exactly() {
        let m = Misses::Spread { transformed: 1861 };
        let n = 1000;
        assert_eq!((0..n).map(|t| m.of(t, n)).sum::<u64>(), 1861);
        assert!((0..n).all(|t| m.of(t, n) <= 2));
    }
}
