//! PLACEHOLDER (replaced by the scene branch's full version at merge).
use std::path::Path;
use super::mesh::{Mesh, Topology};
/// err
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MeshError(pub String);
/// spec
pub fn mesh_from_spec(spec: &str, _base: &Path) -> Result<Mesh, MeshError> {
    let r = spec.strip_prefix("grid:").ok_or_else(|| MeshError(format!("unknown mesh {spec}")))?;
    let (w, h) = r.split_once('x').ok_or_else(|| MeshError("bad".into()))?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| MeshError("bad".into()))?, h.parse().map_err(|_| MeshError("bad".into()))?);
    let mut idx = vec![];
    for y in 0..h { for x in 0..w { let a = y*(w+1)+x; let b=a+1; let c=a+w+1; let d=c+1; idx.extend([a,b,c,b,d,c]); } }
    Ok(Mesh { name: spec.into(), topology: Topology::TriangleList, indices: idx, vertex_count: (w+1)*(h+1) })
}
