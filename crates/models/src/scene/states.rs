//! The state sequence of a scene: per object, in submission order, its
//! (shader, texture, material) ids, for the state-sorting buffer (paper 001,
//! "State Sorting"; `rendersim sortbuf scene:MODEL.toml`).
//!
//! The ids follow the rule for scenes that the frame pipeline's
//! `compile_scene` also uses ([`scene_groups`], [`StateNumbering`];
//! `docs/models.md`, "Scenes"): a preset's groups first, then
//! `[[workload.groups]]`; instance i of a group gets shader
//! `i % shaders`, texture `i % textures`, material `i % materials`, each
//! numbered after the previous groups' ids (a group with `changes` numbers
//! each kind `i * n / count` instead, so that exactly `n` of its draws
//! change it: paper 000 Table 2's counts); `state_order = "sorted"` sorts
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
    /// A group's state ids are not valid (no shaders, textures or
    /// materials; `changes` out of range or beside cycled ids).
    #[error("group {index} ({name}): {what} {message}")]
    GroupStates {
        /// The group's index.
        index: usize,
        /// The group's name.
        name: String,
        /// The field: `shaders`, `textures`, `changes.texture`, ...
        what: &'static str,
        /// What is wrong with it.
        message: String,
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
/// numbered after the previous groups' ids. A group with `changes` instead
/// numbers each kind `i * n / count` for its `n` changes, so that exactly
/// `n` of its draws change it, spread evenly, the first draw among them.
/// Walk the groups in order, calling [`StateNumbering::next_group`] after
/// each.
#[derive(Debug, Clone, Copy, Default)]
pub struct StateNumbering {
    base: ObjectState,
    alpha: u64,
}

/// The id offset of draw `i` of `count` for `n` changes spread evenly:
/// `i * n / count` takes each value 0 to n - 1 once it has begun.
fn spread(i: u64, n: u64, count: u64) -> u64 {
    if count == 0 {
        return 0;
    }
    (i as u128 * n as u128 / count as u128) as u64
}

impl StateNumbering {
    /// The state of instance `i` of group `g` (the current group).
    pub fn state(&self, g: &ObjectGroup, i: u64) -> ObjectState {
        match &g.changes {
            Some(c) => (
                self.base.0.saturating_add(spread(i, c.shader, g.count)),
                self.base.1.saturating_add(spread(i, c.texture, g.count)),
                self.base.2.saturating_add(spread(i, c.material, g.count)),
            ),
            None => (
                self.base.0.saturating_add(i % g.shaders),
                self.base.1.saturating_add(i % g.textures),
                self.base.2.saturating_add(i % g.materials),
            ),
        }
    }

    /// The blending state of instance `i` of group `g`: 0 (opaque) unless
    /// the group gives `changes.alpha`.
    pub fn alpha(&self, g: &ObjectGroup, i: u64) -> u64 {
        match &g.changes {
            Some(c) if c.alpha > 0 => self.alpha.saturating_add(1).saturating_add(spread(i, c.alpha, g.count)),
            _ => 0,
        }
    }

    /// Whether instance `i` of group `g` sets a transformation matrix.
    pub fn sets_matrix(g: &ObjectGroup, i: u64) -> bool {
        match &g.changes {
            Some(c) => c.matrix > 0 && (i == 0 || spread(i, c.matrix, g.count) != spread(i - 1, c.matrix, g.count)),
            None => g.matrix_per_object.unwrap_or(true),
        }
    }

    /// Moves past group `g`'s ids.
    pub fn next_group(&mut self, g: &ObjectGroup) {
        // Saturating: ids cycle over at most `count` instances, so huge
        // `shaders` (or the like) only need to stay apart from the next
        // group's, not to add up exactly.
        let (sh, tx, mt) = match &g.changes {
            Some(c) => {
                self.alpha = self.alpha.saturating_add(c.alpha);
                (c.shader, c.texture, c.material)
            }
            None => (g.shaders, g.textures, g.materials),
        };
        self.base.0 = self.base.0.saturating_add(sh);
        self.base.1 = self.base.1.saturating_add(tx);
        self.base.2 = self.base.2.saturating_add(mt);
    }
}

/// Why group `g`'s state ids are not valid: the field (below the group's
/// key, such as `changes.texture`) and what is wrong with it.
pub fn group_states_error(g: &ObjectGroup) -> Option<(&'static str, String)> {
    for (what, v) in [
        ("shaders", g.shaders),
        ("textures", g.textures),
        ("materials", g.materials),
    ] {
        if v == 0 {
            return Some((what, "must be at least 1".into()));
        }
        if v > 1 && g.changes.is_some() {
            return Some((
                what,
                format!(
                    "is {v}, but the group gives `changes`, which numbers its states itself: give one or the other"
                ),
            ));
        }
    }
    let c = g.changes.as_ref()?;
    if g.matrix_per_object.is_some() {
        return Some((
            "matrix_per_object",
            "is given, but the group gives `changes`, whose `matrix` count says which draws set a matrix: give one or the other".into(),
        ));
    }
    if g.count == 0 {
        return Some((
            "changes",
            "needs draws to change states in, but the group has none (count = 0)".into(),
        ));
    }
    for (what, v, least) in [
        ("changes.shader", c.shader, 1),
        ("changes.texture", c.texture, 1),
        ("changes.material", c.material, 1),
        ("changes.alpha", c.alpha, 0),
        ("changes.matrix", c.matrix, 0),
    ] {
        if v < least || v > g.count {
            return Some((
                what,
                format!("must be {least} to the group's count of draws ({}), got {v}", g.count),
            ));
        }
    }
    None
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
        if let Some((what, message)) = group_states_error(g) {
            return Err(StatesError::GroupStates {
                index: gi,
                name: g.name.clone(),
                what,
                message,
            });
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::config::StateChanges;

    fn group(count: u64, changes: StateChanges) -> ObjectGroup {
        let mut g = crate::scene::presets::preset_groups("city", 1.0).unwrap().remove(0);
        g.count = count;
        g.textures = 1;
        g.materials = 1;
        g.changes = Some(changes);
        g
    }

    fn changes(texture: u64, alpha: u64, matrix: u64) -> StateChanges {
        StateChanges {
            shader: 1,
            texture,
            material: 1,
            alpha,
            matrix,
            sorted_each_frame: false,
        }
    }

    /// The draws of `g` that change texture, alpha and matrix, walking
    /// from a previous group's last state.
    fn counted(g: &ObjectGroup) -> [u64; 3] {
        let mut n = StateNumbering::default();
        // A group before it, so the first draw changes against real ids.
        let before = group(3, changes(2, 1, 1));
        let mut prev = (n.state(&before, 2), n.alpha(&before, 2));
        n.next_group(&before);
        let mut out = [0; 3];
        for i in 0..g.count {
            let (s, a) = (n.state(g, i), n.alpha(g, i));
            out[0] += (s.1 != prev.0.1) as u64;
            out[1] += (a != prev.1) as u64;
            out[2] += StateNumbering::sets_matrix(g, i) as u64;
            prev = (s, a);
        }
        out
    }

    #[test]
    fn changes_are_exactly_the_counts_given_for_any_count() {
        for count in [1u64, 2, 7, 984, 1000] {
            for n in [1, 2, count / 3 + 1, count] {
                let n = n.min(count);
                let g = group(count, changes(n, n, n));
                assert_eq!(counted(&g), [n, n, n], "{n} of {count}");
            }
            // No alpha and no matrix: no matrix set, and opaque throughout
            // (its first draw switches back from the blended draw before).
            assert_eq!(counted(&group(count, changes(1, 0, 0)))[1..], [1, 0]);
        }
    }

    #[test]
    fn changes_out_of_range_or_beside_cycled_ids_are_refused() {
        let g = group(10, changes(11, 0, 0));
        let (what, message) = group_states_error(&g).unwrap();
        assert_eq!(what, "changes.texture");
        assert!(
            message.contains("1 to the group's count of draws (10), got 11"),
            "{message}"
        );
        let mut g = group(10, changes(0, 0, 0));
        assert_eq!(group_states_error(&g).unwrap().0, "changes.texture");
        g.changes = Some(changes(3, 0, 0));
        g.textures = 4;
        let (what, message) = group_states_error(&g).unwrap();
        assert_eq!(what, "textures");
        assert!(message.contains("give one or the other"), "{message}");
        g.textures = 1;
        assert!(group_states_error(&g).is_none());
        g.matrix_per_object = Some(false);
        assert_eq!(group_states_error(&g).unwrap().0, "matrix_per_object");
        g.matrix_per_object = None;
        g.count = 0;
        let (what, message) = group_states_error(&g).unwrap();
        assert_eq!(what, "changes");
        assert!(message.contains("count = 0"), "{message}");
    }

    #[test]
    fn huge_id_counts_do_not_overflow() {
        let mut g = crate::scene::presets::preset_groups("city", 1.0).unwrap().remove(0);
        g.shaders = u64::MAX;
        g.textures = u64::MAX;
        let mut n = StateNumbering::default();
        n.next_group(&g);
        n.next_group(&g);
        assert_eq!(n.state(&g, 5).0, u64::MAX);
    }
}
