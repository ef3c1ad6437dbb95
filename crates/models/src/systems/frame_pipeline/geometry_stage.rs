//! The GPU's geometry stage (paper 000 §4.5): index fetch -> post-transform
//! vertex cache -> vertex shader per actually transformed vertex ->
//! triangle setup, feeding the triangle FIFO. At `triangle` fidelity every
//! triangle is an event, so the bottleneck can move inside one draw
//! (§4.5.1); at `draw` fidelity each draw is one closed form
//! ([`super::closed_form`]) spanning this stage and the fragment stage.
//! With `gpu.fragment.binning = "draw"` the triangle FIFO becomes
//! sort-middle bins: a draw's fragments start after its last triangle's
//! geometry.
//!
//! [`GeometryStage`] owns the stage's state (the draw it holds, the
//! running closed form, the triangle sizes and their random stream) and
//! its transitions; the triangle FIFO, its slot for a triangle held back
//! by a full FIFO and the shader pool come in an [`Env`]. It never calls
//! the fragment stage: a finished triangle is handed back to the step
//! ([`Handoff`]), which starts the fragments, and a closed-form draw says
//! when the fragment stage is busy. [`geometry_cost`] is the one formula of the
//! stage's time, used per mesh by the workload and per triangle here
//! (its own file, below both).

use crate::components::shader_pool::Stream;
use crate::components::shared_bus::SharedBus;
use crate::engine::{Duration, Scheduler, StreamRng, Time};
use crate::scene::config::SizeOrder;
use crate::systems::error::SystemError;

use super::closed_form::DrawTimes;
use super::config::Fidelity;
use super::events::Ev;
use super::geometry_cost::geometry_cost;
use super::links::{Env, FragWork};
use super::unit_specs::GeometrySpec;
use super::workload::{MeshInfo, closed_times, ordered_sizes};

/// `mesh` as a draw from AGP memory sees it at the bus's share now: its
/// geometry time no shorter than its vertices' bytes take to cross the bus
/// (`draw` fidelity; the share is the one at the draw's start).
fn agp_mesh(mesh: &MeshInfo, fetch: f64, bus: &SharedBus, unified: bool) -> MeshInfo {
    let t = Duration::from_ps_f64(mesh.transformed as f64 * fetch / bus.fetch_rate());
    MeshInfo {
        geometry_time: fetch_bound(mesh.geometry_time, mesh.geometry_shader, t, unified),
        ..mesh.clone()
    }
}

/// A geometry time `total` (of which `shader` is vertex shading) when its
/// vertices take `fetch` to cross the bus: the fetch is pipelined with the
/// work, so split it is the longer of the two; unified it runs beside the
/// shading as the fixed-function part does (index fetch, setup), and the
/// longer of those two is the fixed part.
fn fetch_bound(total: Duration, shader: Duration, fetch: Duration, unified: bool) -> Duration {
    if unified {
        shader.saturating_add(total.saturating_sub(shader).max(fetch))
    } else {
        total.max(fetch)
    }
}

/// Where a triangle the geometry stage finished goes (the step acts on it,
/// in this order: the fragments start, then the stage takes its next
/// triangle).
#[derive(Debug, Clone, Copy)]
pub(super) enum Handoff {
    /// Straight to the idle fragment stage; the stage goes on.
    Fragment(FragWork),
    /// Into the triangle FIFO (or its bins); the stage goes on.
    Queued,
    /// Into the link's slot past a full FIFO: the stage blocks until the
    /// fragment stage frees it.
    Held,
    /// No draw (nothing left the stage).
    NoDraw,
}

/// A draw in the geometry stage.
#[derive(Debug, Clone, Copy)]
pub struct ActiveDraw {
    /// Index into the scene's draws.
    pub draw: u32,
    /// Next triangle.
    pub next: u64,
    /// Triangles.
    pub triangles: u64,
    /// Bytes each transformed vertex fetches over the bus (0: the draw's
    /// vertices are in video memory).
    pub fetch: f64,
}

/// The geometry stage.
#[derive(Debug)]
pub struct GeometryStage {
    draw: Option<ActiveDraw>,
    busy: bool,
    /// `draw` fidelity without a trace: the running draw's (geometry,
    /// fragment, total) times, credited to the stage clocks when it ends
    /// instead of with two extra events.
    split: Option<(Duration, Duration, Duration)>,
    /// `draw` fidelity: whether the running draw is fragment-limited (F >= G);
    /// the bottleneck of the whole draw goes to that stage.
    fragment_limited: Option<bool>,
    /// `draw` fidelity: when the running draw ends (its [`Ev::DrawDone`]).
    done_at: Option<Time>,
    /// A finished triangle's fragment work that found the triangle FIFO full.
    /// The running draw's triangle sizes when its group sorts them
    /// (`size_order`), in drawing order; empty otherwise.
    sizes: Vec<f64>,
    pixel_rng: StreamRng,
    /// The size stream's state at the start, restored every frame for a static view.
    pixel_rng_start: Option<StreamRng>,
    /// What it reads of the model.
    spec: GeometrySpec,
}

impl GeometryStage {
    /// An idle stage drawing triangle sizes from `pixel_rng`, restarted at
    /// every frame from `pixel_rng_start` when given (a static view).
    pub(super) fn new(spec: GeometrySpec, pixel_rng: StreamRng, pixel_rng_start: Option<StreamRng>) -> Self {
        GeometryStage {
            spec,
            draw: None,
            busy: false,
            split: None,
            fragment_limited: None,
            done_at: None,
            sizes: Vec::new(),
            pixel_rng,
            pixel_rng_start,
        }
    }

    /// Whether it is transforming (or, at `draw` fidelity, runs a draw's geometry).
    #[inline(always)]
    pub(super) fn busy(&self) -> bool {
        self.busy
    }

    /// Whether it holds a draw.
    #[inline(always)]
    pub(super) fn has_draw(&self) -> bool {
        self.draw.is_some()
    }

    /// The draw it holds (for stall reports).
    pub(super) fn draw(&self) -> Option<ActiveDraw> {
        self.draw
    }

    /// `draw` fidelity: whether the running draw is fragment-limited.
    #[inline(always)]
    pub(super) fn fragment_limited(&self) -> Option<bool> {
        self.fragment_limited
    }

    /// `draw` fidelity: when the running draw ends.
    #[inline(always)]
    pub(super) fn done_at(&self) -> Option<Time> {
        self.done_at
    }

    /// Whether no triangle is in the stage (the triangle link, its held
    /// slot included, and the fragment stage are the caller's to check).
    #[inline]
    pub(super) fn drained(&self) -> bool {
        self.draw.is_none() && !self.busy
    }

    /// A new frame begins (its clear): a static view's triangles get the
    /// same sizes as every other frame's.
    #[inline]
    pub(super) fn new_frame(&mut self) {
        if let Some(start) = &self.pixel_rng_start {
            self.pixel_rng = start.clone();
        }
    }

    /// Takes `draw` from the front end. Returns whether the fragment stage
    /// is busy from now (`draw` fidelity: the draw's closed form spans it).
    pub(super) fn start_draw(
        &mut self,
        now: Time,
        draw: u32,
        env: &mut Env,
        s: &mut Scheduler<Ev>,
    ) -> Result<bool, SystemError> {
        let Some(sc) = &env.scene else {
            return Ok(false);
        };
        let d = &sc.draws[draw as usize];
        let mesh = &sc.meshes[d.mesh as usize];
        let triangles = mesh.triangles;
        let fetch = sc.groups[d.group as usize].fetch_bytes_per_vertex;
        if fetch > 0.0 {
            // From AGP memory: the fetch asks the bus for the draw's bytes
            // over its time alone (all of it for a draw of no time).
            let bytes = mesh.transformed as f64 * fetch;
            let ask = match mesh.geometry_time.0 {
                0 => env.links.bus.capacity(),
                t => bytes / t as f64,
            };
            env.links.bus_changed |= env.links.bus.set_fetch(ask);
        }
        match self.spec.fidelity {
            Fidelity::Triangle => {
                let g = &sc.groups[d.group as usize];
                if g.order == SizeOrder::Random {
                    self.sizes.clear();
                } else {
                    ordered_sizes(g, triangles, &mut self.pixel_rng, &mut self.sizes);
                }
                self.draw = Some(ActiveDraw {
                    draw,
                    next: 0,
                    triangles,
                    fetch,
                });
                self.next_triangle(now, env, s)?;
                Ok(false)
            }
            Fidelity::Draw => {
                let g = &sc.groups[d.group as usize];
                let t = match d.closed {
                    Some(t) => t,
                    None if fetch > 0.0 => {
                        let m = agp_mesh(mesh, fetch, &env.links.bus, self.spec.closed.unified());
                        closed_times(&self.spec.closed, &m, g)
                    }
                    None => closed_times(&self.spec.closed, mesh, g),
                };
                self.start_closed_draw(draw, triangles, t, env.traced, s)
            }
        }
    }

    /// `draw` fidelity: takes `draw` (`triangles` triangles), whose closed
    /// form `t` spans this stage and the fragment stage. Returns whether
    /// the fragment stage is busy from now.
    #[inline(always)]
    pub(super) fn start_closed_draw(
        &mut self,
        draw: u32,
        triangles: u64,
        t: DrawTimes,
        traced: bool,
        s: &mut Scheduler<Ev>,
    ) -> Result<bool, SystemError> {
        self.draw = Some(ActiveDraw {
            draw,
            next: 0,
            triangles,
            fetch: 0.0,
        });
        self.fragment_limited = Some(t.fragment >= t.geometry);
        if !traced {
            // Geometry runs [0, G] and fragments [T - F, T] of the draw;
            // T <= G + F, so the GPU is busy throughout. Without a trace the
            // split is credited at the end (one event).
            self.busy = true;
            self.split = Some((t.geometry, t.fragment, t.total));
            self.done_at = Some(s.after(t.total, Ev::DrawDone, "draw")?);
            return Ok(true);
        }
        self.closed_draw_traced(t, s)
    }

    /// [`GeometryStage::start_closed_draw`] with a trace: the geometry
    /// part's end and the fragment part's start are events of their own, so
    /// the trace shows each stage's span.
    #[inline(never)]
    fn closed_draw_traced(&mut self, t: DrawTimes, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if t.geometry.0 > 0 {
            self.busy = true;
            s.after(t.geometry, Ev::DrawGeometry, "draw geometry")?;
        }
        let frag_start = t.total.saturating_sub(t.fragment);
        if frag_start.0 > 0 {
            s.after(frag_start, Ev::DrawFragmentStart, "draw fragment start")?;
        }
        self.done_at = Some(s.after(t.total, Ev::DrawDone, "draw")?);
        Ok(frag_start.0 == 0)
    }

    /// `draw` fidelity with a trace: the running draw's geometry part ended.
    pub(super) fn closed_geometry_done(&mut self) {
        self.busy = false;
    }

    /// `draw` fidelity: the draw's last fragment is done; this stage is
    /// free (the fragment stage is the caller's to free). Returns the
    /// draw's (geometry, fragment, total) times when they are yet to be
    /// credited to the stage clocks (no trace).
    #[inline]
    pub(super) fn draw_done(&mut self) -> Option<(Duration, Duration, Duration)> {
        let split = self.split.take();
        self.busy = false;
        self.draw = None;
        self.fragment_limited = None;
        self.done_at = None;
        split
    }

    /// Starts the next triangle of the current draw, or finishes the draw.
    pub(super) fn next_triangle(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let Some(a) = self.draw else {
            return Ok(());
        };
        if a.next >= a.triangles {
            self.draw = None;
            // The draw's vertex fetch from AGP memory (if any) ends.
            env.links.bus_changed |= env.links.bus.set_fetch(0.0);
            return Ok(());
        }
        let Some(sc) = &env.scene else {
            return Ok(());
        };
        let mesh = &sc.meshes[sc.draws[a.draw as usize].mesh as usize];
        let tv = mesh.misses.of(a.next, a.triangles);
        let indices = if mesh.indices > 0 { 3 } else { 0 };
        // Checked: a huge per-vertex cost times the vertices must not wrap.
        let mut cost =
            geometry_cost(&self.spec.costs, tv, indices, 1).map_err(|_| crate::engine::TimeError::Overflow {
                context: "computing the geometry time of a triangle (gpu.geometry costs)".into(),
                at: now,
                by: Duration(u64::MAX),
            })?;
        let fetch = a.fetch;
        if fetch > 0.0 && tv > 0 {
            // From AGP memory: no faster than the vertices cross the bus
            // at the share it leaves the fetch now (a fixed-function part).
            let t = Duration::from_ps_f64(tv as f64 * fetch / env.links.bus.fetch_rate());
            cost.total = fetch_bound(cost.total, cost.shader, t, env.links.shaders.is_some());
        }
        self.busy = true;
        if let Some(pool) = &mut env.links.shaders {
            // Unified: fetch and setup beside the vertex shading on the pool.
            pool.begin(now, Stream::Vertex, cost.shader, cost.fixed())?;
            return Ok(());
        }
        s.at(
            now.add(cost.total, "geometry of a triangle")?,
            Ev::GeomTriangle { tag: 0 },
        );
        Ok(())
    }

    /// `triangle` fidelity: a triangle left the stage; its fragment work
    /// goes to the fragment stage (idle unless `frag_busy`), into the
    /// triangle FIFO, or into the link's slot past a full FIFO (the stage
    /// blocks). The step starts the fragments and lets the stage go on
    /// ([`Handoff`]).
    #[inline(always)]
    pub(super) fn triangle_done(&mut self, env: &mut Env, frag_busy: bool) -> Result<Handoff, SystemError> {
        self.busy = false;
        let Some(a) = self.draw.as_mut() else {
            return Ok(Handoff::NoDraw);
        };
        a.next += 1;
        let (next, last, draw) = (a.next, a.next >= a.triangles, a.draw);
        let Some(sc) = &env.scene else {
            return Ok(Handoff::NoDraw);
        };
        let g = &sc.groups[sc.draws[draw as usize].group as usize];
        let px = match self.sizes.get((next - 1) as usize) {
            Some(&px) => px,
            None => g.pixels.sample(&mut self.pixel_rng),
        };
        let links = &mut env.links;
        let f = if links.shaders.is_some() {
            FragWork {
                shader: Duration::from_ps_f64(px * g.shade_per_pixel),
                fixed: Duration::from_ps_f64(px * g.fixed_per_pixel),
            }
        } else {
            FragWork {
                shader: Duration::from_ps_f64(px * g.cost_per_pixel()),
                fixed: Duration::ZERO,
            }
        };
        let fifo = &mut links.triangles;
        Ok(if self.spec.binned {
            // Sort-middle: bin the triangle; the draw's last triangle opens the bins.
            fifo.push(f, 1);
            if last
                && !frag_busy
                && let Some(first) = fifo.pop()
            {
                Handoff::Fragment(first)
            } else {
                Handoff::Queued
            }
        } else if !frag_busy && fifo.is_empty() {
            Handoff::Fragment(f)
        } else if fifo.len() < fifo.capacity() as usize {
            fifo.push(f, 1);
            Handoff::Queued
        } else {
            links.held_triangle = Some(f);
            Handoff::Held
        })
    }
}
