//! Reading a knapsack instance file (`rendersim lod-select INSTANCE.toml`):
//!
//! ```toml
//! budget = "10ms"
//! [[objects]]
//! name = "tree-1"
//! levels = [{ cost = "0.4ms", benefit = 1.0 }, { cost = "1.1ms", benefit = 2.2 }]
//! ```
//!
//! Durations are read by the project's unit parser ([`Duration::parse`]: a
//! unit is required, `0` alone is allowed). Unknown keys, a missing budget,
//! an object without levels, duplicate names, negative or non-finite
//! benefits, benefits whose sum is not finite, and costs that do not parse
//! are errors naming the file, the line and dotted key of the value
//! (`objects.2.levels.0.benefit`, as model files do), and the object (by
//! name and index) and the level. An instance without `[[objects]]` is
//! valid and empty.
//!
//! ```
//! use rendersim_models::components::lod_select::{file::parse_instance, greedy};
//!
//! let inst = parse_instance(
//!     "budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = [{ cost = \"0.4ms\", benefit = 1.0 }]\n",
//! )
//! .unwrap();
//! assert_eq!(greedy(&inst).levels, vec![Some(0)]);
//! ```

use std::collections::HashMap;

use serde::Deserialize;

use super::{Instance, Level, LodObject, LodSelectError};
use crate::engine::Duration;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstance {
    budget: toml::Value,
    #[serde(default)]
    objects: Vec<RawObject>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    name: String,
    levels: Vec<RawLevel>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLevel {
    cost: toml::Value,
    benefit: f64,
}

/// A duration from a TOML or JSON value, read as every model file's
/// durations are (the one parser, [`Duration`]'s `Deserialize`): a string
/// with a unit, or 0.
fn duration(v: &toml::Value) -> Result<Duration, String> {
    Duration::deserialize(v.clone()).map_err(|e| e.to_string())
}

/// Parses an instance file's text. Errors name the key and its line
/// (`instance:4: key `objects.0.levels.1.benefit`: ...`); [`read_instance`]
/// names the file instead of `instance`.
pub fn parse_instance(text: &str) -> Result<Instance, LodSelectError> {
    parse_toml(text, "instance")
}

/// [`parse_instance`] with `file` naming the text in errors.
fn parse_toml(text: &str, file: &str) -> Result<Instance, LodSelectError> {
    let src = crate::config::ModelSource::from_text(file, text);
    let table = src.table().map_err(|e| LodSelectError::File(e.to_string()))?;
    let raw: RawInstance = crate::config::deserialize(&table, &src).map_err(|e| LodSelectError::File(e.to_string()))?;
    build(raw).map_err(|(key, e)| LodSelectError::At {
        file: file.to_string(),
        line: src.line_of(&key),
        key,
        source: Box::new(e),
    })
}

/// Parses the same instance written as JSON (`{"budget": "10ms", "objects":
/// [{"name": ..., "levels": [{"cost": "0.4ms", "benefit": 1.0}]}]}`), for
/// large generated instances: the toml crate reads about 6 MB/s, so a
/// 10,000-object TOML file takes longer to read than to select. Errors
/// name the key (and, for text that does not parse, line and column).
pub fn parse_instance_json(text: &str) -> Result<Instance, LodSelectError> {
    parse_json(text, "instance")
}

fn parse_json(text: &str, file: &str) -> Result<Instance, LodSelectError> {
    let raw: RawInstance = serde_json::from_str(text).map_err(|e| LodSelectError::File(format!("{file}: {e}")))?;
    build(raw).map_err(|(key, e)| LodSelectError::At {
        file: file.to_string(),
        line: None,
        key,
        source: Box::new(e),
    })
}

/// The instance, or the dotted key of the value that is wrong and why.
fn build(raw: RawInstance) -> Result<Instance, (String, LodSelectError)> {
    let budget =
        duration(&raw.budget).map_err(|r| ("budget".to_string(), LodSelectError::File(format!("budget {r}"))))?;
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, o) in raw.objects.iter().enumerate() {
        if let Some(&first) = seen.get(o.name.as_str()) {
            return Err((
                format!("objects.{i}.name"),
                LodSelectError::DuplicateName {
                    name: o.name.clone(),
                    first,
                    second: i,
                },
            ));
        }
        seen.insert(&o.name, i);
    }
    let mut objects = Vec::with_capacity(raw.objects.len());
    for (index, o) in raw.objects.iter().enumerate() {
        let mut levels = Vec::with_capacity(o.levels.len());
        for (level, l) in o.levels.iter().enumerate() {
            let cost = duration(&l.cost).map_err(|reason| {
                (
                    format!("objects.{index}.levels.{level}.cost"),
                    LodSelectError::Cost {
                        object: o.name.clone(),
                        index,
                        level,
                        reason,
                    },
                )
            })?;
            levels.push(Level {
                cost,
                benefit: l.benefit,
            });
        }
        objects.push(LodObject {
            name: o.name.clone(),
            levels,
        });
    }
    Instance::new(budget, objects).map_err(|e| {
        let key = match &e {
            LodSelectError::Benefit { index, level, .. } => format!("objects.{index}.levels.{level}.benefit"),
            LodSelectError::NoLevels { index, .. } => format!("objects.{index}.levels"),
            _ => "objects".to_string(),
        };
        (key, e)
    })
}

/// Reads and parses an instance file: JSON when its name ends in `.json`,
/// TOML otherwise. Errors name the file, the key and (TOML) its line.
pub fn read_instance(path: &std::path::Path) -> Result<Instance, LodSelectError> {
    let text = crate::limits::read_input_string(path, crate::limits::InputKind::Text)
        .map_err(|e| LodSelectError::File(format!("reading {}: {e}", path.display())))?;
    let file = path.display().to_string();
    if path.extension().is_some_and(|e| e == "json") {
        parse_json(&text, &file)
    } else {
        parse_toml(&text, &file)
    }
}
