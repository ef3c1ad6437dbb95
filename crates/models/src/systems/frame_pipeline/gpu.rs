//! The GPU: front end (command processing and state changes), geometry stage
//! (index fetch -> post-transform vertex cache -> vertex shader per actually
//! transformed vertex -> triangle setup), a small triangle FIFO, and the
//! fragment stage (paper 000 §4.5). At `triangle` fidelity every triangle is
//! an event in both stages, so the bottleneck can move inside one draw
//! (§4.5.1); at `draw` fidelity each draw is one closed form
//! ([`super::closed_form`]). With `gpu.fragment.binning = "draw"` the FIFO
//! becomes sort-middle bins: a draw's fragments start after its last
//! triangle's geometry, and the next draw waits for the bins to drain.

use crate::components::preemptible::Wake;
use crate::engine::{Duration, Scheduler, Time};

use super::closed_form::DrawTimes;
use super::config::Fidelity;
use super::model::{ActiveDraw, Command, Ev, FragWork, FramePipeline, FrontPhase, Program};
use super::workload::{closed_times, ordered_sizes};
use crate::components::shader_pool::Stream;
use crate::scene::config::SizeOrder;
use crate::systems::error::SystemError;

impl FramePipeline {
    /// True when no triangle is anywhere between front end and fragment output.
    pub(super) fn pipeline_drained(&self) -> bool {
        self.geom_draw.is_none()
            && self.geom_held.is_none()
            && self.tri_fifo.is_empty()
            && !self.frag_busy
            && !self.geom_busy
    }

    /// Advances the front end as far as it can go now. Returns whether
    /// anything changed.
    pub(super) fn front_step(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        let mut progressed = false;
        loop {
            match self.front_phase {
                FrontPhase::Idle => {
                    let Some(c) = self.fifo.pop() else {
                        return Ok(progressed);
                    };
                    self.commands_executed += self.command_count(&c);
                    self.front_cmd = c;
                    self.front_phase = self.front_begin(now, c, s)?;
                }
                FrontPhase::WaitImage => {
                    if !self.chain.acquire() {
                        return Ok(progressed);
                    }
                    self.front_phase = self.front_start_clear(now, self.front_cmd, s)?;
                }
                FrontPhase::WaitDrain => {
                    if !self.pipeline_drained() {
                        return Ok(progressed);
                    }
                    let work = self.cfg.gpu.swap.saturating_add(self.cfg.gpu.command);
                    self.front_phase = self.front_job(now, self.front_cmd, work, s)?;
                }
                FrontPhase::Handoff => {
                    // Binning: the next draw's geometry waits for the bins to drain.
                    let bins_busy = self.cfg.gpu.fragment.binned() && (self.frag_busy || !self.tri_fifo.is_empty());
                    if self.geom_draw.is_some() || bins_busy {
                        return Ok(progressed);
                    }
                    if let Command::Draw { draw, .. } = self.front_cmd {
                        self.geom_start_draw(now, draw, s)?;
                    }
                    self.front_phase = FrontPhase::Idle;
                }
                FrontPhase::Running => return Ok(progressed),
            }
            progressed = true;
        }
    }

    fn front_begin(&mut self, now: Time, c: Command, s: &mut Scheduler<Ev>) -> Result<FrontPhase, SystemError> {
        let cmd_cost = self.cfg.gpu.command;
        match c {
            Command::Clear { .. } => {
                if self.chain.acquire() {
                    self.front_start_clear(now, c, s)
                } else {
                    Ok(FrontPhase::WaitImage)
                }
            }
            Command::Fixed { gpu, .. } => {
                let work = gpu.saturating_add(cmd_cost);
                self.front_job(now, c, work, s)
            }
            Command::Draw { draw, .. } => {
                let work = match &self.program {
                    Program::Scene(sc) => sc.draws[draw as usize].front,
                    Program::Fixed { .. } => Duration::ZERO,
                };
                self.front_job(now, c, work, s)
            }
            Command::Swap { .. } => Ok(FrontPhase::WaitDrain),
        }
    }

    fn front_start_clear(&mut self, now: Time, c: Command, s: &mut Scheduler<Ev>) -> Result<FrontPhase, SystemError> {
        if let Command::Clear { frame } = c {
            self.gpu_frame = Some(frame);
            if let Some(start) = &self.pixel_rng_start {
                // A static view: this frame's triangles get the same sizes as every other's.
                self.pixel_rng = start.clone();
            }
            self.records[frame as usize].gpu_start = Some(now);
        }
        let mut work = self.cfg.gpu.clear.saturating_add(self.cfg.gpu.command);
        // Per-frame variation (config `variation.gpu`), drawn only when given.
        if let (Command::Clear { .. }, Some(v)) = (c, self.cfg.variation.gpu()) {
            work = work.saturating_add(Duration::from_ps_f64(v.sample(&mut self.variation_rng[1])));
        }
        self.front_job(now, c, work, s)
    }

    /// Runs `work` for command `c` on the (preemptible) front end; zero work
    /// completes at once.
    fn front_job(
        &mut self,
        now: Time,
        c: Command,
        work: Duration,
        s: &mut Scheduler<Ev>,
    ) -> Result<FrontPhase, SystemError> {
        if work.0 > 0 || self.front.in_system() {
            self.start_front_job(now, c, work, s)?;
            return Ok(FrontPhase::Running);
        }
        self.front_after(now, c)
    }

    /// Starts the front end's job of `work` for `c`; its completion is an
    /// event, or quiet when it only starts a hand-off ([`super::quiet`]).
    #[inline(always)]
    pub(super) fn start_front_job(
        &mut self,
        now: Time,
        c: Command,
        work: Duration,
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        match self.front.start_job(now, work)? {
            Wake::JobAt(end, tag) if self.quiet_completion(c, end) => {
                self.front_quiet = Some((s.reserve(end), tag));
            }
            w => Self::schedule_wake(s, w, false),
        }
        Ok(())
    }

    /// The running command's work finished.
    pub(super) fn front_command_done(&mut self, now: Time) -> Result<(), SystemError> {
        if let FrontPhase::Running = self.front_phase {
            self.front_phase = self.front_after(now, self.front_cmd)?;
        }
        Ok(())
    }

    fn front_after(&mut self, now: Time, c: Command) -> Result<FrontPhase, SystemError> {
        Ok(match c {
            Command::Draw { .. } => FrontPhase::Handoff,
            Command::Swap { frame } => {
                self.frame_completed(now, frame)?;
                FrontPhase::Idle
            }
            Command::Clear { .. } | Command::Fixed { .. } => FrontPhase::Idle,
        })
    }

    fn geom_start_draw(&mut self, now: Time, draw: u32, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let Program::Scene(sc) = &self.program else {
            return Ok(());
        };
        let d = &sc.draws[draw as usize];
        let mesh = &sc.meshes[d.mesh as usize];
        let triangles = mesh.triangles;
        match self.cfg.fidelity {
            Fidelity::Triangle => {
                let g = &sc.groups[d.group as usize];
                if g.order == SizeOrder::Random {
                    self.draw_sizes.clear();
                } else {
                    ordered_sizes(g, triangles, &mut self.pixel_rng, &mut self.draw_sizes);
                }
                self.geom_draw = Some(ActiveDraw {
                    draw,
                    next: 0,
                    triangles,
                });
                self.geom_next_triangle(now, s)
            }
            Fidelity::Draw => {
                let t = match d.closed {
                    Some(t) => t,
                    None => closed_times(&self.cfg, mesh, &sc.groups[d.group as usize]),
                };
                self.start_closed_draw(draw, triangles, t, s)
            }
        }
    }

    /// `draw` fidelity: the geometry stage takes `draw` (`triangles`
    /// triangles), whose closed form is `t`.
    #[inline(always)]
    pub(super) fn start_closed_draw(
        &mut self,
        draw: u32,
        triangles: u64,
        t: DrawTimes,
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        self.geom_draw = Some(ActiveDraw {
            draw,
            next: 0,
            triangles,
        });
        self.draw_fragment_limited = Some(t.fragment >= t.geometry);
        if self.acct.trace.is_none() {
            // Geometry runs [0, G] and fragments [T - F, T] of the draw;
            // T <= G + F, so the GPU is busy throughout. Without a trace the
            // split is credited at the end (one event).
            self.geom_busy = true;
            self.frag_busy = true;
            self.draw_split = Some((t.geometry, t.fragment, t.total));
            self.draw_done_at = Some(s.after(t.total, Ev::DrawDone, "draw")?);
            return Ok(());
        }
        self.closed_draw_traced(t, s)
    }

    /// [`FramePipeline::start_closed_draw`] with a trace: the geometry
    /// part's end and the fragment part's start are events of their own, so
    /// the trace shows each stage's span.
    #[inline(never)]
    fn closed_draw_traced(&mut self, t: DrawTimes, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if t.geometry.0 > 0 {
            self.geom_busy = true;
            s.after(t.geometry, Ev::DrawGeometry, "draw geometry")?;
        }
        let frag_start = t.total.saturating_sub(t.fragment);
        if frag_start.0 > 0 {
            s.after(frag_start, Ev::DrawFragmentStart, "draw fragment start")?;
        } else {
            self.frag_busy = true;
        }
        self.draw_done_at = Some(s.after(t.total, Ev::DrawDone, "draw")?);
        Ok(())
    }

    /// `draw` fidelity: the draw's last fragment is done.
    pub(super) fn draw_done(&mut self) {
        if let Some((g, f, t)) = self.draw_split.take() {
            // Both stage clocks have been "busy" since the draw began: keep G
            // (resp. F) of it busy and move the rest to idle.
            self.acct.geom.transfer(0, 2, t.0 - g.0.min(t.0));
            self.acct.frag.transfer(0, 1, t.0 - f.0.min(t.0));
        }
        self.geom_busy = false;
        self.frag_busy = false;
        self.geom_draw = None;
        self.draw_fragment_limited = None;
        self.draw_done_at = None;
    }

    /// Starts the next triangle of the current draw, or finishes the draw.
    fn geom_next_triangle(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let Some(a) = self.geom_draw else {
            return Ok(());
        };
        if a.next >= a.triangles {
            self.geom_draw = None;
            return Ok(());
        }
        let Program::Scene(sc) = &self.program else {
            return Ok(());
        };
        let mesh = &sc.meshes[sc.draws[a.draw as usize].mesh as usize];
        let geo = &self.cfg.gpu.geometry;
        let tv = mesh.misses.of(a.next, a.triangles);
        let fetch = if mesh.indices > 0 {
            geo.index_fetch.checked_mul(3)
        } else {
            Some(Duration(0))
        };
        // Checked: a huge per-vertex cost times the vertices must not wrap.
        let overflow = || crate::engine::TimeError::Overflow {
            context: "computing the geometry time of a triangle (gpu.geometry costs)".into(),
            at: now,
            by: Duration(u64::MAX),
        };
        let fixed = fetch
            .and_then(|f| f.checked_add(geo.triangle_setup))
            .ok_or_else(overflow)?;
        let shader = geo.vertex_shader.checked_mul(tv).ok_or_else(overflow)?;
        self.geom_busy = true;
        if let Some(pool) = &mut self.pool {
            // Unified: fetch and setup beside the vertex shading on the pool.
            pool.begin(now, Stream::Vertex, shader, fixed)?;
            return Ok(());
        }
        let g = shader.checked_add(fixed).ok_or_else(overflow)?;
        s.at(now.add(g, "geometry of a triangle")?, Ev::GeomTriangle { tag: 0 });
        Ok(())
    }

    /// `triangle` fidelity: a triangle left the geometry stage.
    pub(super) fn geom_triangle_done(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.geom_busy = false;
        let Some(a) = self.geom_draw.as_mut() else {
            return Ok(());
        };
        a.next += 1;
        let last = a.next >= a.triangles;
        let draw = a.draw;
        let Program::Scene(sc) = &self.program else {
            return Ok(());
        };
        let g = &sc.groups[sc.draws[draw as usize].group as usize];
        let px = match self.draw_sizes.get((a.next - 1) as usize) {
            Some(&px) => px,
            None => g.pixels.sample(&mut self.pixel_rng),
        };
        let f = if self.pool.is_some() {
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
        if self.cfg.gpu.fragment.binned() {
            // Sort-middle: bin the triangle; the draw's last triangle opens the bins.
            self.tri_fifo.push(f, 1);
            if last
                && !self.frag_busy
                && let Some(first) = self.tri_fifo.pop()
            {
                self.frag_start(now, first, s)?;
            }
        } else if !self.frag_busy && self.tri_fifo.is_empty() {
            self.frag_start(now, f, s)?;
        } else if self.tri_fifo.len() < self.tri_fifo.capacity() as usize {
            self.tri_fifo.push(f, 1);
        } else {
            self.geom_held = Some(f);
            return Ok(());
        }
        self.geom_next_triangle(now, s)
    }

    fn frag_start(&mut self, now: Time, f: FragWork, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.frag_busy = true;
        if let Some(pool) = &mut self.pool {
            pool.begin(now, Stream::Fragment, f.shader, f.fixed)?;
            return Ok(());
        }
        s.at(
            now.add(f.shader, "fragments of a triangle")?,
            Ev::FragTriangle { tag: 0 },
        );
        Ok(())
    }

    /// Unified pool: whether a completion event with `tag` is `stream`'s
    /// current one (and if so, ends the item on the pool). Always true when
    /// split.
    pub(super) fn pool_completes(&mut self, now: Time, stream: Stream, tag: u32) -> bool {
        match &mut self.pool {
            Some(pool) if !pool.is_current(stream, tag) => false,
            Some(pool) => {
                pool.end(now, stream);
                true
            }
            None => true,
        }
    }

    /// Unified pool: after an instant's changes, schedules the completions
    /// whose time moved (stale ones are ignored by their tags).
    #[inline]
    pub(super) fn pool_settle(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        // Split (and `draw` fidelity): no pool, nothing to do, no call.
        if self.pool.is_none() {
            return Ok(());
        }
        self.pool_settle_unified(now, s)
    }

    /// [`FramePipeline::pool_settle`] with a pool.
    #[inline(never)]
    fn pool_settle_unified(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some(pool) = &mut self.pool {
            for d in pool.settle(now)?.iter() {
                s.at(
                    d.at,
                    match d.stream {
                        Stream::Vertex => Ev::GeomTriangle { tag: d.tag },
                        Stream::Fragment => Ev::FragTriangle { tag: d.tag },
                    },
                );
            }
        }
        Ok(())
    }

    /// `triangle` fidelity: the fragment stage finished a triangle.
    pub(super) fn frag_triangle_done(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.frag_busy = false;
        if let Some(f) = self.tri_fifo.pop() {
            self.frag_start(now, f, s)?;
        }
        if let Some(f) = self.geom_held.take() {
            if self.frag_busy {
                self.tri_fifo.push(f, 1);
            } else {
                self.frag_start(now, f, s)?;
            }
            self.geom_next_triangle(now, s)?;
        }
        Ok(())
    }
}
