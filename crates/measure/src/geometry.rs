//! Vertex positions for measured meshes. The generators give index buffers
//! only; positions are synthesized: a grid's vertices on its lattice across
//! the render target (so triangle sizes follow from grid and target size),
//! any other mesh's vertices scattered by a hash of their id.

use crate::scene::mesh::Mesh;

/// Order in which the layers (instances) of a measured mesh are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DepthOrder {
    /// Nearest layer first.
    FrontToBack,
    /// Farthest layer first.
    BackToFront,
    /// A fixed pseudo-random permutation.
    Random,
}

/// A depth order's name that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown depth order {0:?} (front_to_back, back_to_front, random)")]
pub struct UnknownDepthOrder(pub String);

impl std::str::FromStr for DepthOrder {
    type Err = UnknownDepthOrder;
    fn from_str(s: &str) -> Result<Self, UnknownDepthOrder> {
        match s {
            "front_to_back" | "f2b" => Ok(DepthOrder::FrontToBack),
            "back_to_front" | "b2f" => Ok(DepthOrder::BackToFront),
            "random" => Ok(DepthOrder::Random),
            _ => Err(UnknownDepthOrder(s.to_string())),
        }
    }
}

impl DepthOrder {
    /// Depth slot (0 = nearest) of each of `layers` instances in draw order.
    pub fn slots(self, layers: u32) -> Vec<u32> {
        let mut v: Vec<u32> = (0..layers).collect();
        match self {
            DepthOrder::FrontToBack => {}
            DepthOrder::BackToFront => v.reverse(),
            DepthOrder::Random => {
                let mut x = 0x9E37_79B9_7F4A_7C15u64;
                for i in (1..v.len()).rev() {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    v.swap(i, (x % (i as u64 + 1)) as usize);
                }
            }
        }
        v
    }
}

/// Positions in [0, 1]^2 for every vertex of `mesh`, whose generator spec is
/// `spec` (`grid:WxH...` and `strip:WxH` get their lattice).
pub fn mesh_positions(mesh: &Mesh, spec: &str) -> Vec<[f32; 2]> {
    let n = mesh.vertex_count as usize;
    let lattice = spec
        .strip_prefix("grid:")
        .or_else(|| spec.strip_prefix("strip:"))
        .and_then(|r| r.split(':').next())
        .and_then(|wh| wh.split_once('x'))
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match lattice {
        Some((w, h)) if (w as usize + 1) * (h as usize + 1) == n => (0..n)
            .map(|i| {
                let (x, y) = (i % (w as usize + 1), i / (w as usize + 1));
                [x as f32 / w as f32, y as f32 / h as f32]
            })
            .collect(),
        _ => (0..n as u64)
            .map(|i| {
                let mut x = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
                x ^= x >> 29;
                x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                x ^= x >> 32;
                [(x & 0xFFFF) as f32 / 65535.0, ((x >> 16) & 0xFFFF) as f32 / 65535.0]
            })
            .collect(),
    }
}
