//! The GPU's fragment stage (paper 000 §4.5): it shades the triangles the
//! geometry stage puts in the triangle FIFO, one at a time (on the shader
//! pool beside its fixed-function work when the architecture is unified).
//! When the FIFO is full the geometry stage holds its next triangle; a
//! triangle finished here makes room and lets it go on. At `draw` fidelity
//! the stage is busy over the fragment part of each draw's closed form
//! ([`super::closed_form`]), which the geometry stage starts.
//!
//! [`FragmentStage`] owns whether the stage is busy and its transitions;
//! the triangle FIFO, the link's slot for a held triangle and the shader
//! pool come in an [`Env`]. It never calls the geometry stage: freeing a
//! held triangle, it says so, and the step lets geometry go on.

use crate::components::shader_pool::{ShaderPool, Stream};
use crate::engine::{Scheduler, Time};
use crate::systems::error::SystemError;

use super::events::Ev;
use super::links::{Env, FragWork};

/// The fragment stage.
#[derive(Debug, Default)]
pub struct FragmentStage {
    busy: bool,
}

impl FragmentStage {
    /// Whether it is shading.
    #[inline(always)]
    pub(super) fn busy(&self) -> bool {
        self.busy
    }

    /// `draw` fidelity: the running draw's fragment part began (`true`) or
    /// the draw ended (`false`).
    #[inline(always)]
    pub(super) fn set_closed_busy(&mut self, busy: bool) {
        self.busy = busy;
    }

    /// `triangle` fidelity: starts shading a triangle's fragments `f`.
    pub(super) fn start(
        &mut self,
        now: Time,
        f: FragWork,
        shaders: &mut Option<ShaderPool>,
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        self.busy = true;
        if let Some(pool) = shaders {
            pool.begin(now, Stream::Fragment, f.shader, f.fixed)?;
            return Ok(());
        }
        s.at(
            now.add(f.shader, "fragments of a triangle")?,
            Ev::FragTriangle { tag: 0 },
        );
        Ok(())
    }

    /// `triangle` fidelity: a triangle is shaded. The next one comes from
    /// the triangle FIFO; a triangle held back by a full FIFO (the link's
    /// slot) goes in, or straight here. Returns whether it freed one (the
    /// geometry stage, blocked on it, goes on).
    #[inline(always)]
    pub(super) fn triangle_done(
        &mut self,
        now: Time,
        env: &mut Env,
        s: &mut Scheduler<Ev>,
    ) -> Result<bool, SystemError> {
        self.busy = false;
        let links = &mut env.links;
        if let Some(f) = links.triangles.pop() {
            self.start(now, f, &mut links.shaders, s)?;
        }
        let Some(f) = links.held_triangle.take() else {
            return Ok(false);
        };
        if self.busy {
            links.triangles.push(f, 1);
        } else {
            self.start(now, f, &mut links.shaders, s)?;
        }
        Ok(true)
    }
}
