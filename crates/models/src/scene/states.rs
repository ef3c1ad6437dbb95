//! The state sequence of a scene: per object, in submission order, its
//! (shader, texture, material) ids, for the state-sorting buffer (paper 001,
//! "State Sorting"; `rendersim sortbuf scene:MODEL.toml`).
//!
//! The ids follow the rule for scenes that the frame pipeline's
//! `compile_scene` also uses ([`scene_groups`], [`StateNumbering`];
//! `docs/models.md`, "Scenes"): a preset's groups first, then
//! `[[workload.groups]]`; instance i of a group gets shader
//! `i % shaders`, texture `i % textures`, material `i % materials`, each
//! numbered after the previous groups' ids; `state_order = "sorted"` sorts
//! the objects by (shader, texture, material). `tests/it/sortbuf.rs`
//! checks the changes this sequence implies against the pipeline's own
//! counts.

use crate::config::ConfigError;
use crate::limits::{MAX_SCENE_OBJECTS, MAX_SCENE_SCALE};
use crate::scene::config::{ObjectGroup, SceneWorkload, StateOrder};
use crate::scene::presets::{PRESETS, preset_groups};

/// (shader, texture, material) of one object.
pub type ObjectState = (u64, u64, u64);

/// What `scene:SPEC` should look like.
const EXPECTED: &str = "expected scene:MODEL.toml[:state|shader|texture|material]";

/// Why a scene's state sequence cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum StatesError {
    /// `workload.preset` names no preset.
    #[error("unknown preset {name:?} (known: {known})", known = PRESETS.join(", "))]
    UnknownPreset {
        /// The name given.
        name: String,
    },
    /// The preset could not be expanded (the error says why).
    #[error("workload.preset: {0}")]
    Preset(#[source] Box<StatesError>),
    /// `workload.scale` is out of range.
    #[error("workload.scale: must be a number > 0 and <= {max}, got {0}", max = MAX_SCENE_SCALE)]
    Scale(f64),
    /// More objects than the limit.
    #[error("the scene has {0} objects, more than the limit of {max}", max = MAX_SCENE_OBJECTS)]
    TooManyObjects(u64),
    /// A group with no shaders, textures or materials.
    #[error("group {index} ({name}): {what} must be at least 1")]
    NoIds {
        /// The group's index.
        index: usize,
        /// The group's name.
        name: String,
        /// `shaders`, `textures` or `materials`.
        what: &'static str,
    },
    /// `scene:` names no model file.
    #[error("scene:{spec}: names no model file before the attribute; {EXPECTED}")]
    NoModelFile {
        /// The spec after `scene:`.
        spec: String,
    },
    /// `scene:` names a folder.
    #[error("scene:{spec}: {path} is a folder, not a model file; {EXPECTED}")]
    Folder {
        /// The spec after `scene:`.
        spec: String,
        /// The path it names.
        path: String,
    },
    /// The model file could not be loaded.
    #[error(transparent)]
    Load(#[from] ConfigError),
    /// The model has no `[workload]`.
    #[error("{path}: the model has no [workload] table, so no scene to take states from")]
    NoWorkload {
        /// The model file.
        path: String,
    },
    /// The model's workload is not a scene.
    #[error("{path}: workload.kind is not \"scene\", so there is no scene to take states from")]
    NotAScene {
        /// The model file.
        path: String,
    },
    /// `[workload]` does not read as a scene.
    #[error("{path}: reading [workload]: {message}")]
    Workload {
        /// The model file.
        path: String,
        /// What did not read.
        message: String,
    },
    /// The model file's scene is not valid (the error says why).
    #[error("{path}: {source}")]
    Scene {
        /// The model file.
        path: String,
        /// Why.
        source: Box<StatesError>,
    },
}

/// A scene's groups in submission order: the preset's (if any), then
/// `[[workload.groups]]`. The error is the message for `workload.preset`.
pub fn scene_groups(scene: &SceneWorkload) -> Result<Vec<ObjectGroup>, StatesError> {
    let mut groups = Vec::new();
    if let Some(p) = &scene.preset {
        groups.extend(preset_groups(p, scene.scale).ok_or_else(|| StatesError::UnknownPreset { name: p.clone() })?);
    }
    groups.extend(scene.groups.iter().cloned());
    Ok(groups)
}

/// The state numbering of a scene: instance `i` of a group gets shader
/// `i % shaders`, texture `i % textures`, material `i % materials`, each
/// numbered after the previous groups' ids. Walk the groups in order,
/// calling [`StateNumbering::next_group`] after each.
#[derive(Debug, Clone, Copy, Default)]
pub struct StateNumbering {
    base: ObjectState,
}

impl StateNumbering {
    /// The state of instance `i` of group `g` (the current group).
    pub fn state(&self, g: &ObjectGroup, i: u64) -> ObjectState {
        (
            self.base.0 + i % g.shaders,
            self.base.1 + i % g.textures,
            self.base.2 + i % g.materials,
        )
    }

    /// Moves past group `g`'s ids.
    pub fn next_group(&mut self, g: &ObjectGroup) {
        self.base.0 += g.shaders;
        self.base.1 += g.textures;
        self.base.2 += g.materials;
    }
}

/// The scene's objects' states in submission order, or why the scene is
/// not valid.
pub fn state_sequence(scene: &SceneWorkload) -> Result<Vec<ObjectState>, StatesError> {
    if !(scene.scale.is_finite() && scene.scale > 0.0 && scene.scale <= MAX_SCENE_SCALE) {
        return Err(StatesError::Scale(scene.scale));
    }
    let groups = scene_groups(scene).map_err(|e| StatesError::Preset(Box::new(e)))?;
    let total: u64 = groups.iter().map(|g| g.count).fold(0, u64::saturating_add);
    if total > MAX_SCENE_OBJECTS {
        return Err(StatesError::TooManyObjects(total));
    }
    let mut out = Vec::with_capacity(total as usize);
    let mut numbering = StateNumbering::default();
    for (gi, g) in groups.iter().enumerate() {
        for (what, v) in [
            ("shaders", g.shaders),
            ("textures", g.textures),
            ("materials", g.materials),
        ] {
            if v == 0 {
                return Err(StatesError::NoIds {
                    index: gi,
                    name: g.name.clone(),
                    what,
                });
            }
        }
        out.extend((0..g.count).map(|i| numbering.state(g, i)));
        numbering.next_group(g);
    }
    if scene.state_order == StateOrder::Sorted {
        out.sort();
    }
    Ok(out)
}

/// The state ids of a model file's scene in submission order, numbered by
/// first appearance: `spec` is `MODEL.toml[:state|shader|texture|material]`
/// (relative paths from `base`); `state` (the default) numbers the whole
/// (shader, texture, material) triple, the others one attribute. This is
/// `rendersim sortbuf scene:...`'s sequence and the `sorting_buffer`
/// system's. Errors name the file and what is missing.
pub fn scene_state_ids(spec: &str, base: &std::path::Path) -> Result<Vec<u64>, StatesError> {
    use crate::config::{Overrides, load_model};
    let (path, attr) = match spec.rsplit_once(':') {
        Some((p, a)) if ["state", "shader", "texture", "material"].contains(&a) => (p, a),
        _ => (spec, "state"),
    };
    if path.is_empty() {
        return Err(StatesError::NoModelFile { spec: spec.to_string() });
    }
    let full = base.join(path);
    if full.is_dir() {
        return Err(StatesError::Folder {
            spec: spec.to_string(),
            path: path.to_string(),
        });
    }
    let model = load_model(Some(&full), &Overrides::default())?;
    let path = path.to_string();
    let Some(w) = model.table.get("workload").and_then(|v| v.as_table()) else {
        return Err(StatesError::NoWorkload { path });
    };
    if w.get("kind").and_then(|k| k.as_str()) != Some("scene") {
        return Err(StatesError::NotAScene { path });
    }
    let mut w = w.clone();
    w.remove("kind");
    let scene: SceneWorkload = match toml::Value::Table(w).try_into() {
        Ok(s) => s,
        Err(e) => {
            return Err(StatesError::Workload {
                path,
                message: e.to_string(),
            });
        }
    };
    let states = state_sequence(&scene).map_err(|e| StatesError::Scene {
        path,
        source: Box::new(e),
    })?;
    let mut ids: std::collections::HashMap<ObjectState, u64> = std::collections::HashMap::new();
    Ok(states
        .into_iter()
        .map(|(sh, tx, mt)| {
            let key = match attr {
                "shader" => (sh, 0, 0),
                "texture" => (0, tx, 0),
                "material" => (0, 0, mt),
                _ => (sh, tx, mt),
            };
            let n = ids.len() as u64;
            *ids.entry(key).or_insert(n)
        })
        .collect())
}
