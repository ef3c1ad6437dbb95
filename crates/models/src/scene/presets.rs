//! Synthetic scenes shaped after paper 000 Table 5 (city, terrain, forest).
//!
//! The paper gives, per scene, objects / triangles / actually transformed
//! vertices per triangle / textures / state switches:
//! city 5609 / 3,453,465 / 1.86 / 88 / 14267; terrain 1 / 86,400 / 0.99 / 1 / 1;
//! forest 157 / 579,644 / 1.78 / 2 / 314. The meshes here are described by
//! those statistics (triangle count and transformed vertices per triangle),
//! not by real index buffers. Screen-space triangle sizes are not in the
//! paper; the distributions below are this project's choice and are stated
//! in `docs/models.md`.

use crate::components::distribution::Dist;
use crate::config::Bytes;
use crate::scene::config::{MeshRef, ObjectGroup};

/// Names of the presets.
pub const PRESETS: &[&str] = &["city", "terrain", "forest"];

fn scaled(n: u64, scale: f64) -> u64 {
    ((n as f64 * scale).round() as u64).max(1)
}

/// The object groups of preset `name` at `scale` (fraction of the paper's
/// object count), or `None` for an unknown name.
pub fn preset_groups(name: &str, scale: f64) -> Option<Vec<ObjectGroup>> {
    let group = |name: &str, count: u64, tris: u64, acmr: f64, pixels: Dist<f64>, tex: u64, mat: u64| ObjectGroup {
        name: name.to_string(),
        count,
        mesh: MeshRef::Stats { triangles: tris, acmr },
        indexed: true,
        triangle_pixels: pixels,
        size_order: Default::default(),
        shaders: 1,
        textures: tex,
        materials: mat,
        matrix_per_object: None,
        geometry_upload: Bytes(0),
        texture_upload: Bytes(0),
        geometry_memory: Default::default(),
        vertex_bytes: Bytes(32),
        changes: None,
    };
    Some(match name {
        // 3,453,465 / 5609 = 616 triangles per building.
        "city" => vec![group(
            "buildings",
            scaled(5609, scale),
            616,
            1.86,
            Dist::Lognormal {
                median: 20.0,
                sigma: 1.5,
            },
            88,
            3,
        )],
        // One 86,400-triangle terrain mesh, strips adapted to the cache.
        "terrain" => vec![group(
            "terrain",
            1,
            scaled(86_400, scale),
            0.99,
            Dist::Lognormal {
                median: 8.0,
                sigma: 0.8,
            },
            1,
            1,
        )],
        // 579,644 / 157 = 3692 triangles per tree; strongly varying sizes.
        "forest" => vec![group(
            "trees",
            scaled(157, scale),
            3692,
            1.78,
            Dist::Lognormal {
                median: 6.0,
                sigma: 2.0,
            },
            2,
            2,
        )],
        _ => return None,
    })
}
