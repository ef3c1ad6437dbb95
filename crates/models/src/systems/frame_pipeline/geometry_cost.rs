//! The geometry stage's one formula of time (paper 000 §4.5): index fetch,
//! vertex shading per transformed vertex, triangle setup, from the model's
//! per-index, per-vertex and per-triangle costs. The workload compiles each
//! mesh's time with it and the geometry stage each triangle's, so it sits
//! below both.

use crate::engine::Duration;

use super::config::GeometryConfig;

/// The geometry stage's time for some work: its vertex-shader part and the
/// whole (the rest is index fetch and triangle setup).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GeometryCost {
    /// Vertex shading.
    pub shader: Duration,
    /// Index fetch, vertex shading and triangle setup.
    pub total: Duration,
}

impl GeometryCost {
    /// The fixed-function part (index fetch and triangle setup).
    #[inline(always)]
    pub fn fixed(&self) -> Duration {
        Duration(self.total.0 - self.shader.0)
    }
}

/// Which part of [`geometry_cost`] left the 64-bit picosecond range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostOverflow {
    /// A cost times its count.
    Product,
    /// A sum of costs.
    Sum,
}

/// The geometry stage's time for `transformed` vertices shaded (those the
/// post-transform cache missed), `indices` indices fetched and `triangles`
/// triangles set up, from the model's per-vertex, per-index and
/// per-triangle costs (`gpu.geometry`). The first part to overflow is
/// reported, in the order: shading, fetch, fetch + shading, setup, total.
#[inline]
pub fn geometry_cost(
    geo: &GeometryConfig,
    transformed: u64,
    indices: u64,
    triangles: u64,
) -> Result<GeometryCost, CostOverflow> {
    let shader = geo
        .vertex_shader
        .checked_mul(transformed)
        .ok_or(CostOverflow::Product)?;
    let fetch = geo.index_fetch.checked_mul(indices).ok_or(CostOverflow::Product)?;
    let fetched = fetch.checked_add(shader).ok_or(CostOverflow::Sum)?;
    let setup = geo.triangle_setup.checked_mul(triangles).ok_or(CostOverflow::Product)?;
    let total = fetched.checked_add(setup).ok_or(CostOverflow::Sum)?;
    Ok(GeometryCost { shader, total })
}
