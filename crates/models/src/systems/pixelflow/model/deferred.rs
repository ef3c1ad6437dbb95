//! The deferred-shading architectures' step (standard and presort, paper
//! 002 §4-5): per rasterizing node geometry (standard: the whole frame,
//! bucket sorted; presort: the sorting pass, then instructions generated
//! region by region), then per region rasterize, composite over the
//! network into the shader of `region mod shaders`, shade, send the colour
//! back and load it into frame-buffer memory.

use crate::engine::{Duration, Scheduler};
use crate::systems::error::SystemError;

use super::{Ev, PixelFlow, mul};
use crate::systems::pixelflow::config::Architecture;

impl PixelFlow {
    pub(super) fn settle_deferred(&mut self, sched: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        let mut moved = false;
        let c = self.cfg.deferred.clone();
        let now = sched.now();
        // A frame starts on every rasterizer at one instant (one head-pose
        // sample): once every node may start it.
        let all_may_start = (0..self.nodes).all(|r| self.geometry_may_start(r));
        for r in 0..self.nodes {
            if all_may_start {
                let f = self.geom_frame[r] as usize;
                let p = self.layout.prims[r];
                let (per, name) = match self.cfg.architecture {
                    Architecture::Standard => (c.t_trans, "geometry + bucket sort"),
                    _ => (c.t_first_pass, "sorting pass"),
                };
                let d = c.t_overhead.saturating_add(mul(per, p, name)?);
                self.geom_busy[r] = true;
                self.busy.geometry[r] = self.busy.geometry[r].saturating_add(d);
                let ft = &mut self.frame_times[f].0;
                *ft = Some(ft.map_or(now, |t| t.min(now)));
                self.work(sched, d, Ev::GeomDone(r as u32), 0, r as u32, name, f as u32)?;
                moved = true;
            }
            // Presort: generate the next region's instructions.
            if self.cfg.architecture == Architecture::Presort
                && !self.geom_busy[r]
                && !self.gen_busy[r]
                && (self.gen_ready[r] as usize) < self.sorted[r] as usize * self.regions
            {
                let g = self.gen_ready[r] as usize;
                let j = g % self.regions;
                let entries = self.layout.bin(r, j);
                let total = self.layout.node_entries(r).max(1);
                // The node's t_gen_each x primitives, spread over its regions
                // in proportion to their entries (cumulative rounding).
                let p = self.layout.prims[r] as u128;
                let before: u64 = (0..j).map(|k| self.layout.bin(r, k)).sum();
                let ps = c.t_gen_each.0 as u128 * p;
                let t0 = (ps * before as u128 / total as u128) as u64;
                let t1 = (ps * (before + entries) as u128 / total as u128) as u64;
                let d = Duration(t1 - t0);
                self.gen_busy[r] = true;
                self.busy.generate[r] = self.busy.generate[r].saturating_add(d);
                self.gen_end[r] = self.work(
                    sched,
                    d,
                    Ev::GenDone(r as u32),
                    0,
                    r as u32,
                    "generate instructions",
                    g as u32,
                )?;
                moved = true;
            }
            let j = self.rast_next[r];
            // Presort streams a region's instructions to the pixel array as
            // they are generated (the DMA fetches them "as needed", §3): the
            // rasterization may start with the generation and ends no earlier
            // than one primitive after it.
            let streaming = self.gen_busy[r] && self.gen_ready[r] == j;
            if !self.rast_busy[r]
                && (j as usize) < self.total
                && (self.gen_ready[r] > j || streaming)
                && self.comp_next >= j
            {
                let work = mul(
                    c.t_rast_per_prim,
                    self.layout.bin(r, j as usize % self.regions),
                    "rasterization",
                )?;
                let d = self.begin_rasterize(r, work, c.t_rast_per_prim, now, streaming);
                self.work(sched, d, Ev::RastDone(r as u32), 1, r as u32, "rasterize", j)?;
                moved = true;
            }
        }
        let j = self.comp_next as usize;
        if !self.net_busy && j < self.total && self.region_rast[j] as usize == self.nodes {
            let s = j % self.shaders;
            if !self.shader_reserved[s] {
                self.shader_reserved[s] = true;
                self.net_busy = true;
                self.comp_next += 1;
                let d = mul(c.t_comp_byte, c.appearance_bytes as u64, "composition")?;
                self.busy.composite = self.busy.composite.saturating_add(d);
                self.records[j].comp_start = Some(now);
                self.work(sched, d, Ev::CompDone(j as u32), 3, 0, "composite appearance", j as u32)?;
                moved = true;
            }
        }
        for s in 0..self.shaders {
            if self.shader_busy[s].is_none()
                && let Some(j) = self.shader_ready[s].take()
            {
                self.shader_reserved[s] = false;
                self.shader_busy[s] = Some(j);
                let d = c.t_shade_address.saturating_add(c.t_shade_texture);
                self.busy.shade[s] = self.busy.shade[s].saturating_add(d);
                self.records[j as usize].shade_start = Some(now);
                self.work(sched, d, Ev::ShadeDone(s as u32), 2, s as u32, "shade", j)?;
                moved = true;
            }
        }
        if self.color_busy.is_none()
            && let Some(j) = self.color_queue.pop_front()
        {
            self.color_busy = Some(j);
            let d = mul(c.t_comp_byte, c.color_bytes as u64, "color transfer")?;
            self.busy.color = self.busy.color.saturating_add(d);
            self.work(sched, d, Ev::ColorDone(j), 3, 1, "send color", j)?;
            moved = true;
        }
        Ok(moved)
    }
}
