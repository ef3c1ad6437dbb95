//! The non-texturing architecture's step (paper 002 §6): per node,
//! geometry and rasterization in batches into the completely instanced
//! frame buffer; for every further sample the stored instructions are
//! rasterized again after the previous sample's whole-screen composition;
//! the last composition runs region by region, pipelined with the loads.

use crate::engine::Scheduler;
use crate::systems::error::SystemError;

use super::{Ev, PixelFlow, mul};

impl PixelFlow {
    pub(super) fn settle_nontex(&mut self, sched: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        let mut moved = false;
        let c = self.cfg.nontex.clone();
        let now = sched.now();
        if self.pass == 1 {
            for r in 0..self.nodes {
                if !self.geom_busy[r] && self.geom_batches[r] < self.batches[r] && self.geom_batches[r] > 0 {
                    let k = self.geom_batches[r];
                    let d = mul(c.t_trans, self.batch_prims(r, k), "geometry")?;
                    self.geom_busy[r] = true;
                    self.busy.geometry[r] = self.busy.geometry[r].saturating_add(d);
                    self.gen_end[r] =
                        self.work(sched, d, Ev::BatchGeomDone(r as u32), 0, r as u32, "geometry", k as u32)?;
                    moved = true;
                }
                // The pixel array takes instructions as the geometry
                // processor writes them (§6: "completely pipelined"): a batch
                // may start while it is generated and ends no earlier than one
                // primitive after its geometry.
                let streaming = self.geom_busy[r] && self.rast_batches[r] == self.geom_batches[r];
                if !self.rast_busy[r] && (self.rast_batches[r] < self.geom_batches[r] || streaming) {
                    let k = self.rast_batches[r];
                    let work = mul(c.t_rast_per_prim, self.batch_entries(r, k), "rasterization")?;
                    let d = self.begin_rasterize(r, work, c.t_rast_per_prim, now, streaming);
                    self.work(
                        sched,
                        d,
                        Ev::BatchRastDone(r as u32),
                        1,
                        r as u32,
                        "rasterize sample 1",
                        k as u32,
                    )?;
                    moved = true;
                }
            }
        }
        // Final sample: composite region by region, pipelined with the loads.
        if self.final_comp && !self.net_busy && (self.comp_next as usize) < self.regions {
            let j = self.comp_next as usize;
            self.comp_next += 1;
            self.net_busy = true;
            let d = mul(c.t_comp_byte, c.composite_bytes as u64, "composition")?;
            self.busy.composite = self.busy.composite.saturating_add(d);
            self.records[j].comp_start = Some(now);
            self.work(sched, d, Ev::CompDone(j as u32), 3, 0, "composite colors", j as u32)?;
            moved = true;
        }
        Ok(moved)
    }

    /// Nontex: every node finished rasterizing the current sample.
    pub(super) fn nontex_pass_done(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let now = sched.now();
        if self.pass == 1 {
            self.front_end_done = now;
            self.frame_times[0].1 = now;
        }
        for rec in &mut self.records {
            rec.rasterized = Some(now);
        }
        self.pass_done_nodes = 0;
        if self.pass >= self.cfg.samples.max(1) {
            self.final_comp = true;
            return Ok(());
        }
        let c = &self.cfg.nontex;
        let per_region = mul(c.t_comp_byte, c.composite_bytes as u64, "composition")?;
        let d = mul(per_region, self.regions as u64, "composition")?;
        self.busy.composite = self.busy.composite.saturating_add(d);
        self.work(sched, d, Ev::PassCompDone, 3, 0, "composite sample", self.pass)?;
        Ok(())
    }
}
