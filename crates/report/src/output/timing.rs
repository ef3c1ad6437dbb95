//! Wall times in outputs, and how to fix them for sets compared byte for
//! byte (issue 60 item 11).
//!
//! A run's outputs are the same bytes for the same model and seed except
//! for what measures the machine or the occasion: the provenance's date
//! (fixed by `SOURCE_DATE_EPOCH`, [`super::provenance`]) and the wall times
//! (seconds building and simulating, events a second, a walkthrough's
//! estimator costs, an experiment's wall time). When `SOURCE_DATE_EPOCH` is
//! set, or the global `--no-timing` flag is given (it sets
//! `RENDERSIM_NO_TIMING`, and dates the provenance 1970-01-01 unless
//! `SOURCE_DATE_EPOCH` gives a date), every such number is written as 0, so
//! that two result sets of one command compare equal with `cmp`.
//!
//! ```
//! use rendersim_report::output::timing::zero_wall_times;
//!
//! let mut v = serde_json::json!({"wall_seconds": 1.5, "metrics": {"fps": 60.0, "build_seconds": 0.2}});
//! zero_wall_times(&mut v);
//! assert_eq!(v, serde_json::json!({"wall_seconds": 0.0, "metrics": {"fps": 60.0, "build_seconds": 0.0}}));
//! ```

/// Keys, at any depth of a JSON summary, whose numbers measure the machine
/// or the occasion (their names as every system writes them).
pub const WALL_TIME_KEYS: [&str; 13] = [
    "wall_seconds",
    "build_seconds",
    "simulate_seconds",
    "simulating_seconds",
    "calibrate_seconds",
    "events_per_second",
    "measuring_over_simulating",
    "cost_us_per_frame",
    "vcs_preprocess_seconds",
    "pvc_preprocess_seconds",
    "sim_wall_seconds",
    "array_wall_seconds",
    "cpu_seconds",
];

/// Whether wall times are written as 0: `SOURCE_DATE_EPOCH` or
/// `RENDERSIM_NO_TIMING` is set (to anything but an empty string).
pub fn timing_fixed() -> bool {
    ["SOURCE_DATE_EPOCH", "RENDERSIM_NO_TIMING"]
        .iter()
        .any(|k| std::env::var_os(k).is_some_and(|v| !v.is_empty()))
}

/// `seconds`, or 0 when [`timing_fixed`].
pub fn wall(seconds: f64) -> f64 {
    if timing_fixed() { 0.0 } else { seconds }
}

/// Sets every number under a [`WALL_TIME_KEYS`] key of `v`, at any depth,
/// to 0 (whatever [`timing_fixed`] says: callers ask it).
pub fn zero_wall_times(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m.iter_mut() {
                if WALL_TIME_KEYS.contains(&k.as_str()) {
                    zero_numbers(x);
                } else {
                    zero_wall_times(x);
                }
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(zero_wall_times),
        _ => {}
    }
}

fn zero_numbers(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Number(_) => *v = serde_json::json!(0.0),
        serde_json::Value::Object(m) => m.values_mut().for_each(zero_numbers),
        serde_json::Value::Array(a) => a.iter_mut().for_each(zero_numbers),
        _ => {}
    }
}

/// [`zero_wall_times`] when [`timing_fixed`].
pub fn fix_wall_times(v: &mut serde_json::Value) {
    if timing_fixed() {
        zero_wall_times(v);
    }
}
