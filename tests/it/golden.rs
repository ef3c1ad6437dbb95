//! Golden outputs: every model in `models/` (seed 1) and every experiment in
//! `experiments/` run through the CLI, compared byte for byte with the
//! outputs stored under `tests/golden/` — the guard for restructurings that
//! must not change behaviour.
//!
//! Compared: each model's `summary.json` (without its wall-time keys and
//! its provenance: revision, command line, date), `frames.csv` and
//! `model.toml` (the repository's path written `$ROOT`, without the
//! provenance comment at its head);
//! each experiment's `runs.csv` and `points.csv` without their wall-time
//! columns (`wall_seconds*`, `*speedup`, build, simulation and calibration
//! times), and its `searches.csv` if any. A file of at most 16 KiB is stored
//! whole (so a failure shows a diff); a larger one as its length and FNV-1a
//! hash (`NAME.fnv`). `RENDERSIM_BLESS=1 cargo test --release --test it golden::` rewrites
//! the stored outputs after an intended change: say why in the commit.

use std::path::{Path, PathBuf};
use std::process::Command;

use rayon::prelude::*;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const WHOLE_LIMIT: usize = 16 * 1024;
/// Summary keys that measure the machine or the occasion, not the model.
const WALL_KEYS: [&str; 5] = [
    "wall_seconds",
    "build_seconds",
    "simulate_seconds",
    "events_per_second",
    "provenance",
];
/// Keys at any depth that measure the machine (the walkthrough's estimator
/// costs and view-cell preprocess times), removed wherever they occur; experiment columns naming one are
/// left out too.
const NESTED_WALL_KEYS: [&str; 3] = ["cost_us_per_frame", "vcs_preprocess_seconds", "pvc_preprocess_seconds"];
/// Experiment columns (metric paths) that measure the machine: the
/// fidelity-models experiment's build and simulation times, the
/// device-predictions experiment's simulating and calibration times.
const COLUMN_WALL_KEYS: [&str; 5] = [
    "build_seconds",
    "simulate_seconds",
    "simulating_seconds",
    "calibrate_seconds",
    "measuring_over_simulating",
];

fn remove_nested(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            for k in NESTED_WALL_KEYS {
                m.remove(k);
            }
            m.values_mut().for_each(remove_nested);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(remove_nested),
        _ => {}
    }
}

fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

fn run(args: &[&str], out: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(args)
        .arg("--out")
        .arg(out)
        .current_dir(ROOT)
        .output()
        .unwrap();
    // Experiments whose checks fail still write their outputs (exit 1).
    assert!(
        o.status.success() || (args[0] == "experiment" && o.status.code() == Some(1)),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn summary(path: &Path) -> Vec<u8> {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    if let Some(m) = v.as_object_mut() {
        for k in WALL_KEYS {
            m.remove(k);
        }
    }
    remove_nested(&mut v);
    let mut s = serde_json::to_string_pretty(&v).unwrap();
    s.push('\n');
    s.into_bytes()
}

fn without_wall_columns(path: &Path) -> Vec<u8> {
    let mut r = csv::ReaderBuilder::new().has_headers(false).from_path(path).unwrap();
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    let Some(header) = rows.first() else {
        return Vec::new();
    };
    let keep: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| {
            !(h.starts_with("wall_seconds")
                || h.ends_with("speedup")
                || NESTED_WALL_KEYS.iter().any(|k| h.contains(k))
                || COLUMN_WALL_KEYS.iter().any(|k| h.contains(k)))
        })
        .map(|(i, _)| i)
        .collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in &rows {
        w.write_record(keep.iter().map(|&i| row.get(i).unwrap_or(""))).unwrap();
    }
    w.into_inner().unwrap()
}

/// The normalized outputs of one model or experiment: (file name, bytes).
fn outputs(kind: &str, file: &Path, tmp: &Path) -> Vec<(String, Vec<u8>)> {
    let rel = file.strip_prefix(ROOT).unwrap().to_str().unwrap().to_string();
    let out = tmp.join(file.file_stem().unwrap());
    if kind == "models" {
        run(&["run", &rel, "--seed", "1"], &out);
        let text = std::fs::read_to_string(out.join("model.toml")).unwrap();
        // The provenance comment (this build, the command, the date) goes.
        let model = text
            .lines()
            .skip_while(|l| l.starts_with("# Written by ") || l.starts_with("# Command: "))
            .map(|l| format!("{l}\n"))
            .collect::<String>()
            .replace(ROOT, "$ROOT");
        assert!(text.starts_with("# Written by rendersim "), "{text}");
        vec![
            ("summary.json".into(), summary(&out.join("summary.json"))),
            ("frames.csv".into(), std::fs::read(out.join("frames.csv")).unwrap()),
            ("model.toml".into(), model.into_bytes()),
        ]
    } else {
        run(&["experiment", &rel, "--quiet"], &out);
        let mut v = vec![
            ("runs.csv".into(), without_wall_columns(&out.join("runs.csv"))),
            ("points.csv".into(), without_wall_columns(&out.join("points.csv"))),
        ];
        if out.join("searches.csv").exists() {
            v.push(("searches.csv".into(), std::fs::read(out.join("searches.csv")).unwrap()));
        }
        v
    }
}

fn stored_form(name: &str, bytes: &[u8]) -> (String, Vec<u8>) {
    if bytes.len() <= WHOLE_LIMIT {
        (name.to_string(), bytes.to_vec())
    } else {
        (
            format!("{name}.fnv"),
            format!("{} bytes, fnv1a64 {:016x}\n", bytes.len(), fnv1a(bytes)).into_bytes(),
        )
    }
}

fn toml_files(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_model_and_experiment_gives_its_golden_outputs() {
    let bless = std::env::var_os("RENDERSIM_BLESS").is_some();
    let tmp = tempfile::tempdir().unwrap();
    // RENDERSIM_GOLDEN_ONLY=a,b: only the models and experiments with these
    // file stems (to bless a new one without rerunning every other).
    let only: Option<Vec<String>> = std::env::var("RENDERSIM_GOLDEN_ONLY")
        .ok()
        .map(|v| v.split(',').map(|s| s.trim().to_string()).collect());
    let cases: Vec<(&str, PathBuf)> = ["models", "experiments"]
        .into_iter()
        .flat_map(|kind| toml_files(kind).into_iter().map(move |p| (kind, p)))
        .filter(|(_, p)| {
            only.as_ref()
                .is_none_or(|o| o.iter().any(|s| p.file_stem().is_some_and(|f| f == s.as_str())))
        })
        .collect();
    let golden = Path::new(ROOT).join("tests/golden");
    let mismatches: Vec<String> = cases
        .par_iter()
        .flat_map_iter(|(kind, file)| {
            let stem = file.file_stem().unwrap().to_str().unwrap().to_string();
            let dir = golden.join(kind).join(&stem);
            let scratch = tmp.path().join(kind);
            outputs(kind, file, &scratch)
                .into_iter()
                .filter_map(move |(name, bytes)| {
                    let (stored_name, stored) = stored_form(&name, &bytes);
                    let path = dir.join(&stored_name);
                    // The other form (the whole file beside its hash, or a
                    // hash beside the whole file) is stale.
                    let other = if stored_name == name {
                        format!("{name}.fnv")
                    } else {
                        name.clone()
                    };
                    let stale = dir.join(&other);
                    if bless {
                        std::fs::create_dir_all(&dir).unwrap();
                        std::fs::write(&path, &stored).unwrap();
                        let _ = std::fs::remove_file(&stale);
                        return None;
                    }
                    if stale.exists() {
                        return Some(format!(
                            "{kind}/{stem}/{other}: stale beside {stored_name} (bless removes it)"
                        ));
                    }
                    match std::fs::read(&path) {
                        Ok(old) if old == stored => None,
                        Ok(old) => {
                            let first = old
                                .iter()
                                .zip(&stored)
                                .position(|(a, b)| a != b)
                                .unwrap_or(old.len().min(stored.len()));
                            let line = 1 + stored[..first].iter().filter(|&&b| b == b'\n').count();
                            Some(format!(
                                "{kind}/{stem}/{stored_name}: differs from line {line} on ({} bytes stored, {} now)",
                                old.len(),
                                stored.len()
                            ))
                        }
                        Err(_) => Some(format!("{kind}/{stem}/{stored_name}: no stored golden (bless it)")),
                    }
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        mismatches.is_empty(),
        "outputs differ from tests/golden ({} files); if the change is intended, rerun with RENDERSIM_BLESS=1 and say why in the commit:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
}
