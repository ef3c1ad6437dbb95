//! Shared hardware sections: a model's top-level `hardware = "PATH"` names
//! a TOML file (relative to the model's folder) whose tables describe a
//! machine, `[cpu]`, `[command_fifo]`, `[gpu]`, `[bus]` and `[display]`
//! and their sub-tables. They are merged under the model's own tables key
//! by key, so a model states only what its scene or setting changes, and
//! one calibrated device (`models/hardware/geforce3.toml`, paper 000's
//! GeForce3) is used unchanged by every model that names it. A key the
//! model gives itself wins; arrays and values are replaced whole, never
//! merged. A hardware file cannot name another one.
//!
//! Errors in a value that came from the hardware file name that file and
//! the value's line there ([`hardware_line_of`], used by
//! [`super::invalid`]).

use std::path::PathBuf;

use super::load::{ConfigError, ModelSource, invalid};

/// The top-level key that names a hardware file.
pub const HARDWARE_KEY: &str = "hardware";

/// The tables a hardware file may hold.
pub const HARDWARE_SECTIONS: [&str; 5] = ["cpu", "command_fifo", "gpu", "bus", "display"];

/// The hardware file `table`'s `hardware` key names, as a source, or an
/// error naming the key in `src`.
fn hardware_source(src: &ModelSource, value: &toml::Value) -> Result<ModelSource, ConfigError> {
    let Some(path) = value.as_str() else {
        return Err(invalid(
            src,
            HARDWARE_KEY,
            format!(
                "must be the path of a TOML file of hardware sections (e.g. \"hardware/geforce3.toml\"), got {value}"
            ),
            None,
        ));
    };
    let full: PathBuf = src.base_dir.join(path);
    ModelSource::from_file(&full).map_err(|e| match e {
        ConfigError::Io { source, .. } => invalid(
            src,
            HARDWARE_KEY,
            format!("cannot read {}: {source}", full.display()),
            None,
        ),
        e => e,
    })
}

/// Merges `hw` under `model`: keys `model` lacks are taken from `hw`,
/// tables present in both are merged the same way, anything else in
/// `model` stays.
fn merge_under(model: &mut toml::Table, hw: toml::Table) {
    for (k, v) in hw {
        match (model.get_mut(&k), v) {
            (None, v) => {
                model.insert(k, v);
            }
            (Some(toml::Value::Table(m)), toml::Value::Table(h)) => merge_under(m, h),
            (Some(_), _) => {}
        }
    }
}

/// Takes `hardware` out of `table` (parsed from `src`) and merges the
/// file it names under the rest.
pub(crate) fn merge_hardware(src: &ModelSource, table: &mut toml::Table) -> Result<(), ConfigError> {
    let Some(value) = table.remove(HARDWARE_KEY) else {
        return Ok(());
    };
    let hw_src = hardware_source(src, &value)?;
    let hw = hw_src.own_table()?;
    for key in hw.keys() {
        let message = if key == HARDWARE_KEY {
            "a hardware file cannot name another hardware file".to_string()
        } else if !HARDWARE_SECTIONS.contains(&key.as_str()) {
            format!(
                "is not a hardware section (a hardware file holds only {}; put it in the model)",
                HARDWARE_SECTIONS.join(", ")
            )
        } else if !hw[key].is_table() {
            "must be a table".to_string()
        } else {
            continue;
        };
        return Err(ConfigError::Invalid {
            file: hw_src.name.clone(),
            key: key.clone(),
            line: hw_src.line_of(key),
            message,
            suggestion: None,
        });
    }
    merge_under(table, hw);
    Ok(())
}

/// The hardware file of `src` and the line where `key` stands in it, when
/// the model names a readable hardware file that holds `key`.
pub fn hardware_line_of(src: &ModelSource, key: &str) -> Option<(String, usize)> {
    let own = src.own_table().ok()?;
    let value = own.get(HARDWARE_KEY)?;
    let hw = hardware_source(src, value).ok()?;
    hw.line_of(key).map(|line| (hw.name.clone(), line))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model_in(dir: &std::path::Path, model: &str, hw: &str) -> ModelSource {
        std::fs::write(dir.join("hw.toml"), hw).unwrap();
        std::fs::write(dir.join("m.toml"), model).unwrap();
        ModelSource::from_file(&dir.join("m.toml")).unwrap()
    }

    #[test]
    fn the_models_keys_win_and_tables_merge() {
        let d = tempfile::tempdir().unwrap();
        let src = model_in(
            d.path(),
            "hardware = \"hw.toml\"\n[gpu]\nclear = \"1ms\"\n[gpu.fragment]\nper_fragment = \"2ns\"\n",
            "[gpu]\nclear = \"9ms\"\nswap = \"20us\"\n[gpu.fragment]\nper_fragment = \"1ns\"\nfifo_depth = 4\n[cpu]\nclear = \"5us\"\n",
        );
        let t = src.table().unwrap();
        assert!(t.get(HARDWARE_KEY).is_none());
        assert_eq!(t["gpu"]["clear"].as_str(), Some("1ms"));
        assert_eq!(t["gpu"]["swap"].as_str(), Some("20us"));
        assert_eq!(t["gpu"]["fragment"]["per_fragment"].as_str(), Some("2ns"));
        assert_eq!(t["gpu"]["fragment"]["fifo_depth"].as_integer(), Some(4));
        assert_eq!(t["cpu"]["clear"].as_str(), Some("5us"));
    }

    #[test]
    fn a_value_from_the_hardware_file_is_blamed_on_its_line() {
        let d = tempfile::tempdir().unwrap();
        let src = model_in(
            d.path(),
            "hardware = \"hw.toml\"\n",
            "# a device\n[gpu]\nswap = \"x\"\n",
        );
        let (file, line) = hardware_line_of(&src, "gpu.swap").unwrap();
        assert!(file.ends_with("hw.toml"), "{file}");
        assert_eq!(line, 3);
        let e = invalid(&src, "gpu.swap", "bad".into(), None).to_string();
        assert!(e.contains("hw.toml:3: key `gpu.swap`: bad"), "{e}");
    }

    #[test]
    fn bad_hardware_files_are_refused_by_name() {
        let d = tempfile::tempdir().unwrap();
        let cases = [
            (
                "hardware = 3\n",
                "[gpu]\n",
                "m.toml:1: key `hardware`: must be the path",
            ),
            ("hardware = \"none.toml\"\n", "[gpu]\n", "key `hardware`: cannot read"),
            (
                "hardware = \"hw.toml\"\n",
                "[workload]\nkind = \"fixed\"\n",
                "hw.toml:1: key `workload`: is not a hardware section",
            ),
            (
                "hardware = \"hw.toml\"\n",
                "hardware = \"hw.toml\"\n",
                "hw.toml:1: key `hardware`: a hardware file cannot name another",
            ),
            (
                "hardware = \"hw.toml\"\n",
                "gpu = 3\n",
                "hw.toml:1: key `gpu`: must be a table",
            ),
            ("hardware = \"hw.toml\"\n", "[gpu\n", "hw.toml: malformed TOML"),
        ];
        for (model, hw, want) in cases {
            let e = model_in(d.path(), model, hw).table().unwrap_err().to_string();
            assert!(e.contains(want), "{model:?} {hw:?}: {e}");
        }
    }
}
