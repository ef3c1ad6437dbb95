//! The page's controls: the frame pipeline's main knobs, each a model key
//! with its unit and the range its slider spans, and the value the model
//! gives it.
//!
//! A control sets its key exactly as `--set` does (`cpu.per_object="5us"`),
//! and the server checks the value with the model's own checks, so a bad
//! value is refused with `--set`'s message. The slider's range is a
//! teaching range, not the key's validity: a value typed outside it still
//! goes to the model's checks. A control whose key the model does not use
//! (a scene's keys on a fixed workload) is left out; keys that are off
//! unless given (a frame limiter, VRR, frame generation) start off.

use serde::Serialize;

/// What a control's value is and how it is written into `--set`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Kind {
    /// A duration written with `unit` (`"5us"`).
    Duration {
        /// `s`, `ms`, `us`, `ns`.
        unit: &'static str,
        /// The slider's lowest value, in `unit`.
        min: f64,
        /// The slider's highest value, in `unit`.
        max: f64,
        /// The slider's step, in `unit`.
        step: f64,
    },
    /// A rate written in hertz (`"60Hz"`).
    Rate {
        /// Lowest, Hz.
        min: f64,
        /// Highest, Hz.
        max: f64,
        /// Step, Hz.
        step: f64,
    },
    /// A whole number.
    Int {
        /// Lowest.
        min: i64,
        /// Highest.
        max: i64,
    },
    /// A number.
    Float {
        /// Lowest.
        min: f64,
        /// Highest.
        max: f64,
        /// Step.
        step: f64,
    },
    /// `true` or `false`.
    Bool,
    /// One of `options` (a TOML string).
    Choice {
        /// The values, as the model writes them.
        options: &'static [&'static str],
    },
}

/// One control of the page.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Control {
    /// The model key it sets (`cpu.per_object`).
    pub key: &'static str,
    /// What a student reads beside it.
    pub label: &'static str,
    /// The panel it sits in.
    pub group: &'static str,
    /// Its kind, unit and slider range.
    pub kind: Kind,
    /// Off unless given (`pacing.limit`): the page shows a switch, and
    /// without it the key is not set at all.
    pub optional: bool,
    /// A scene's knob (per object, per draw, vertex and fragment costs,
    /// the shader pool): left out for a fixed or replayed workload, whose
    /// model still carries the key but never uses it.
    pub scene_only: bool,
}

const fn c(key: &'static str, label: &'static str, group: &'static str, kind: Kind) -> Control {
    Control {
        key,
        label,
        group,
        kind,
        optional: false,
        scene_only: false,
    }
}

/// A scene's knob ([`Control::scene_only`]).
const fn scene(key: &'static str, label: &'static str, group: &'static str, kind: Kind) -> Control {
    Control {
        scene_only: true,
        ..c(key, label, group, kind)
    }
}

const fn opt(key: &'static str, label: &'static str, group: &'static str, kind: Kind) -> Control {
    Control {
        optional: true,
        ..c(key, label, group, kind)
    }
}

const fn ms(min: f64, max: f64, step: f64) -> Kind {
    Kind::Duration {
        unit: "ms",
        min,
        max,
        step,
    }
}

const fn us(min: f64, max: f64, step: f64) -> Kind {
    Kind::Duration {
        unit: "us",
        min,
        max,
        step,
    }
}

const fn ns(min: f64, max: f64, step: f64) -> Kind {
    Kind::Duration {
        unit: "ns",
        min,
        max,
        step,
    }
}

const HZ: Kind = Kind::Rate {
    min: 20.0,
    max: 360.0,
    step: 1.0,
};

/// Every control the page can show, in the order of a frame's data flow
/// (CPU, command FIFO, GPU, display, pacing), then the run's own.
pub const CONTROLS: &[Control] = &[
    c("cpu.non_render", "CPU work per frame", "CPU", ms(0.1, 50.0, 0.1)),
    scene("cpu.per_object", "CPU work per object", "CPU", us(0.0, 200.0, 1.0)),
    scene("cpu.per_draw", "CPU work per draw call", "CPU", us(0.0, 200.0, 1.0)),
    c("workload.cpu", "CPU work per frame", "CPU", ms(0.0, 50.0, 0.1)),
    c(
        "cpu.max_frames_ahead",
        "frames the CPU may run ahead",
        "CPU",
        Kind::Int { min: 1, max: 8 },
    ),
    c(
        "command_fifo.capacity",
        "command FIFO depth",
        "CPU",
        Kind::Int { min: 1, max: 4096 },
    ),
    scene(
        "gpu.architecture",
        "GPU architecture",
        "GPU",
        Kind::Choice {
            options: &["unified", "split"],
        },
    ),
    scene("gpu.geometry.vertex_shader", "vertex cost", "GPU", ns(0.0, 500.0, 1.0)),
    scene("gpu.fragment.per_fragment", "fragment cost", "GPU", ns(0.0, 50.0, 0.1)),
    c("workload.gpu", "GPU work per frame", "GPU", ms(0.0, 50.0, 0.1)),
    c(
        "workload.scale",
        "triangles (scene scale)",
        "GPU",
        Kind::Float {
            min: 0.1,
            max: 5.0,
            step: 0.1,
        },
    ),
    c(
        "workload.depth_complexity",
        "pixels (depth complexity)",
        "GPU",
        Kind::Float {
            min: 1.0,
            max: 10.0,
            step: 0.1,
        },
    ),
    c(
        "display.present_mode",
        "present mode",
        "display",
        Kind::Choice {
            options: &["fifo", "fifo_latest_ready", "mailbox", "immediate"],
        },
    ),
    c("display.vsync", "vsync", "display", Kind::Bool),
    c("display.buffers", "buffers", "display", Kind::Int { min: 2, max: 4 }),
    c("display.refresh", "refresh", "display", HZ),
    c(
        "display.composition",
        "composition",
        "display",
        Kind::Choice {
            options: &["independent", "composed"],
        },
    ),
    opt(
        "display.vrr.min_refresh",
        "VRR: lowest refresh",
        "display",
        Kind::Rate {
            min: 20.0,
            max: 144.0,
            step: 1.0,
        },
    ),
    opt(
        "display.vrr.max_refresh",
        "VRR: highest refresh (default: refresh)",
        "display",
        Kind::Rate {
            min: 48.0,
            max: 360.0,
            step: 1.0,
        },
    ),
    opt("pacing.limit", "frame limiter", "pacing", HZ),
    c(
        "pacing.limit_from",
        "limiter waits before",
        "pacing",
        Kind::Choice {
            options: &["start", "present", "submit"],
        },
    ),
    c("pacing.low_latency", "low-latency pacing", "pacing", Kind::Bool),
    c("frame_generation.enabled", "frame generation", "pacing", Kind::Bool),
    c(
        "frame_generation.cost",
        "frame generation cost",
        "pacing",
        ms(0.0, 10.0, 0.1),
    ),
    c("noise.enabled", "system noise", "run", Kind::Bool),
    c(
        "fidelity",
        "fidelity",
        "run",
        Kind::Choice {
            options: &["draw", "triangle"],
        },
    ),
    c("run.frames", "frames", "run", Kind::Int { min: 100, max: 3000 }),
    c("run.seed", "seed", "run", Kind::Int { min: 0, max: 1_000_000 }),
];

/// Keys a model may leave out that are still worth a control: they are off,
/// or at their default, until set (`None`: off).
fn default_of(key: &str) -> Option<toml::Value> {
    Some(match key {
        "pacing.limit_from" => toml::Value::String("start".into()),
        "pacing.low_latency" | "frame_generation.enabled" => toml::Value::Boolean(false),
        "frame_generation.cost" => toml::Value::String("1ms".into()),
        "display.composition" => toml::Value::String("independent".into()),
        "gpu.architecture" => toml::Value::String("unified".into()),
        _ => return None,
    })
}

/// A control with its value in the model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Shown {
    /// The control.
    #[serde(flatten)]
    pub control: Control,
    /// The key `--set` writes: the control's key, or its distribution's
    /// `median`, `mean` or `value` where the model gives a distribution
    /// (`cpu.non_render.median`).
    pub set_key: String,
    /// The model's value in the control's unit (a number, `true`/`false`
    /// or a choice); `null` for an optional control that is off.
    pub value: serde_json::Value,
}

/// The value at dotted `key` of `table`.
fn lookup<'a>(table: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let mut parts = key.split('.');
    let mut v = table.get(parts.next()?)?;
    for p in parts {
        v = v.as_table()?.get(p)?;
    }
    Some(v)
}

/// `text` (a duration as the model writes it, `"100us"`) in `unit`.
fn duration_in(text: &str, unit: &str) -> Option<f64> {
    let d = crate::engine::Duration::parse(text).ok()?.0;
    let per = match unit {
        "s" => 1e12,
        "ms" => 1e9,
        "us" => 1e6,
        "ns" => 1e3,
        _ => return None,
    };
    Some(d as f64 / per)
}

/// `text` (a rate, `"60Hz"` or a period) in hertz.
fn rate_hz(text: &str) -> Option<f64> {
    // A frequency's period is kept in whole picoseconds: 60 Hz reads back
    // as 59.99999999; six decimals give the 60 written.
    let hz = crate::config::units::Rate::parse(text).ok()?.hz();
    Some((hz * 1e6).round() / 1e6)
}

/// The controls that apply to `resolved` (a model as `rendersim run`
/// writes `model.toml`: every key it uses given), with their values;
/// `scene`: whether its workload is a scene.
pub fn shown(resolved: &toml::Table, scene: bool) -> Vec<Shown> {
    CONTROLS
        .iter()
        .filter(|c| scene || !c.scene_only)
        .filter_map(|c| show(c, resolved))
        .collect()
}

fn show(c: &Control, resolved: &toml::Table) -> Option<Shown> {
    let given = lookup(resolved, c.key).cloned();
    let (set_key, value) = match (given, c.optional) {
        (None, true) => (c.key.to_string(), None),
        (None, false) => (c.key.to_string(), Some(default_of(c.key)?)),
        // A distribution: its centre is the knob.
        (Some(toml::Value::Table(t)), _) => {
            let part = ["median", "mean", "value"].into_iter().find(|p| t.contains_key(*p))?;
            (format!("{}.{part}", c.key), Some(t[part].clone()))
        }
        (Some(v), _) => (c.key.to_string(), Some(v)),
    };
    let value = match value {
        None => serde_json::Value::Null,
        Some(v) => in_unit(&c.kind, &v)?,
    };
    Some(Shown {
        control: *c,
        set_key,
        value,
    })
}

/// The model's value `v` as the control shows it; `None` where it is not
/// of the control's kind (the control is then left out).
fn in_unit(kind: &Kind, v: &toml::Value) -> Option<serde_json::Value> {
    use serde_json::json;
    Some(match (kind, v) {
        (Kind::Duration { unit, .. }, toml::Value::String(s)) => json!(duration_in(s, unit)?),
        (Kind::Rate { .. }, toml::Value::String(s)) => json!(rate_hz(s)?),
        (Kind::Int { .. }, toml::Value::Integer(i)) => json!(i),
        (Kind::Float { .. }, toml::Value::Float(f)) => json!(f),
        (Kind::Float { .. }, toml::Value::Integer(i)) => json!(*i as f64),
        (Kind::Bool, toml::Value::Boolean(b)) => json!(b),
        (Kind::Choice { options }, toml::Value::String(s)) if options.contains(&s.as_str()) => json!(s),
        _ => return None,
    })
}

/// The `--set` assignment a control writes for `value` (a number in the
/// control's unit, `true`/`false`, or a choice), or why the value is not of
/// the control's kind. The page's `assignmentOf` (page/app.js) writes the
/// same form; `tests/it/explore.rs` runs every control's slider ends
/// through this one.
pub fn assignment(c: &Control, set_key: &str, value: &str) -> Result<String, String> {
    let number = || {
        value
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{}: {value:?} is not a number", c.key))
    };
    Ok(match c.kind {
        Kind::Duration { unit, .. } => format!("{set_key}=\"{}{unit}\"", number()?),
        Kind::Rate { .. } => format!("{set_key}=\"{}Hz\"", number()?),
        Kind::Int { .. } | Kind::Float { .. } => {
            number()?;
            format!("{set_key}={}", value.trim())
        }
        Kind::Bool => match value.trim() {
            "true" | "false" => format!("{set_key}={}", value.trim()),
            _ => return Err(format!("{}: {value:?} is not true or false", c.key)),
        },
        Kind::Choice { options } => {
            if !options.contains(&value) {
                return Err(format!("{}: {value:?} is not one of {}", c.key, options.join(", ")));
            }
            format!("{set_key}=\"{value}\"")
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolved(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn a_distribution_is_controlled_by_its_centre_and_absent_keys_are_left_out() {
        let t = resolved(
            "[cpu]\nnon_render = { kind = \"lognormal\", median = \"3ms\", sigma = 0.15 }\nper_object = \"5us\"\n[display]\nrefresh = \"60Hz\"\n",
        );
        let s = shown(&t, true);
        let non_render = s.iter().find(|s| s.control.key == "cpu.non_render").unwrap();
        assert_eq!(non_render.set_key, "cpu.non_render.median");
        assert_eq!(non_render.value, serde_json::json!(3.0));
        let refresh = s.iter().find(|s| s.control.key == "display.refresh").unwrap();
        assert_eq!(refresh.value, serde_json::json!(60.0));
        // A fixed workload's key is not in a scene model; an optional key is off.
        assert!(s.iter().all(|s| s.control.key != "workload.gpu"));
        let limit = s.iter().find(|s| s.control.key == "pacing.limit").unwrap();
        assert_eq!(limit.value, serde_json::Value::Null);
    }

    #[test]
    fn assignments_carry_the_unit_and_refuse_what_is_not_of_the_kind() {
        let per_object = CONTROLS.iter().find(|c| c.key == "cpu.per_object").unwrap();
        assert_eq!(
            assignment(per_object, "cpu.per_object", "7.5").unwrap(),
            "cpu.per_object=\"7.5us\""
        );
        assert!(
            assignment(per_object, "cpu.per_object", "x")
                .unwrap_err()
                .contains("not a number")
        );
        let mode = CONTROLS.iter().find(|c| c.key == "display.present_mode").unwrap();
        assert!(assignment(mode, "display.present_mode", "fast").is_err());
        let limit = CONTROLS.iter().find(|c| c.key == "pacing.limit").unwrap();
        assert_eq!(
            assignment(limit, "pacing.limit", "50").unwrap(),
            "pacing.limit=\"50Hz\""
        );
    }
}
