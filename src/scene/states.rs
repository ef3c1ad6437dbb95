//! The state sequence of a scene: per object, in submission order, its
//! (shader, texture, material) ids, for the state-sorting buffer (paper 001,
//! "State Sorting"; `rendersim sortbuf scene:MODEL.toml`).
//!
//! The ids follow the frame pipeline's rule for scenes
//! (`systems::frame_pipeline::workload::compile_scene`, described in
//! `docs/models.md`, "Scenes"): a preset's groups first, then
//! `[[workload.groups]]`; instance i of a group gets shader
//! `i % shaders`, texture `i % textures`, material `i % materials`, each
//! numbered after the previous groups' ids; `state_order = "sorted"` sorts
//! the objects by (shader, texture, material). `tests/it/sortbuf.rs`
//! checks the changes this sequence implies against the pipeline's own
//! counts.

use crate::limits::{MAX_SCENE_OBJECTS, MAX_SCENE_SCALE};
use crate::scene::config::{SceneWorkload, StateOrder};
use crate::scene::presets::{PRESETS, preset_groups};

/// (shader, texture, material) of one object.
pub type ObjectState = (u64, u64, u64);

/// The scene's objects' states in submission order, or why the scene is
/// not valid.
pub fn state_sequence(scene: &SceneWorkload) -> Result<Vec<ObjectState>, String> {
    if !(scene.scale.is_finite() && scene.scale > 0.0 && scene.scale <= MAX_SCENE_SCALE) {
        return Err(format!(
            "workload.scale: must be a number > 0 and <= {MAX_SCENE_SCALE}, got {}",
            scene.scale
        ));
    }
    let mut groups = Vec::new();
    if let Some(p) = &scene.preset {
        groups.extend(
            preset_groups(p, scene.scale)
                .ok_or_else(|| format!("workload.preset: unknown preset {p:?} (known: {})", PRESETS.join(", ")))?,
        );
    }
    groups.extend(scene.groups.iter().cloned());
    let total: u64 = groups.iter().map(|g| g.count).fold(0, u64::saturating_add);
    if total > MAX_SCENE_OBJECTS {
        return Err(format!(
            "the scene has {total} objects, more than the limit of {MAX_SCENE_OBJECTS}"
        ));
    }
    let mut out = Vec::with_capacity(total as usize);
    let (mut sb, mut tb, mut mb) = (0u64, 0u64, 0u64);
    for (gi, g) in groups.iter().enumerate() {
        for (what, v) in [
            ("shaders", g.shaders),
            ("textures", g.textures),
            ("materials", g.materials),
        ] {
            if v == 0 {
                return Err(format!("group {gi} ({}): {what} must be at least 1", g.name));
            }
        }
        for i in 0..g.count {
            out.push((sb + i % g.shaders, tb + i % g.textures, mb + i % g.materials));
        }
        sb += g.shaders;
        tb += g.textures;
        mb += g.materials;
    }
    if scene.state_order == StateOrder::Sorted {
        out.sort();
    }
    Ok(out)
}
