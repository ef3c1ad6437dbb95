//! Mutations at the edges of the file system and the process (issue 60),
//! where the text of an input is fine but where it comes from or where
//! the output goes is not:
//!
//! - **endless and huge inputs**: every kind of input file given as
//!   `/dev/zero`, `/dev/urandom`, a FIFO nobody writes, a link to a device,
//!   a folder, a sparse file past the default size limit, or a real file
//!   past `--max-input-bytes` (also a model whose `hardware = ` names one,
//!   and a shard file of a split replaced by one); each must be refused
//!   before it is read, naming the file;
//! - **captures that should be questioned**: every row twice, stamps
//!   before zero (refused); a column named twice (refused, naming it, where
//!   the replay reads it; else the same replay); stamps shifted near 2^63
//!   and the file in UTF-16 (the same replay to 1e-6 as the file before);
//! - **output paths inside another command's result set** (a run's, an
//!   experiment's, a replay's), written directly, through `.`/`..`, or
//!   absolutely, by every command that writes a file: refused, and the set
//!   byte for byte as it was;
//! - **a full standard output** (`/dev/full`) under every command that
//!   prints: a clean error naming standard output, not a panic or a
//!   silent exit 0.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use rand::{Rng, seq::IndexedRandom};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::{Case, ROOT};

/// Bounds that keep a run of `models/fixed.toml` small.
const FIXED: [&str; 4] = ["--set", "run.frames=20", "--set", "run.warmup_frames=2"];

/// What the edge cases start from: endless and huge stand-ins for files,
/// three finished result sets, and the captures.
pub struct Edges {
    /// `tree/edges`: FIFOs, links to devices, folders and sparse files
    /// with each input kind's extension.
    dir: PathBuf,
    /// Result sets to write into: (kind, folder).
    sets: Vec<(&'static str, PathBuf)>,
    /// Captures (name, text) from `tests/fixtures/presentmon`.
    captures: Vec<(String, String)>,
    /// The sharded fixture experiment and its finished split.
    shard_experiment: PathBuf,
    shard_out: PathBuf,
}

const EXTS: [&str; 5] = ["toml", "csv", "obj", "idx", "json"];

/// Makes the stand-ins and the result sets inside `tree` (with `bin`).
pub fn prepare(tree: &Path, bin: &Path, shard_experiment: &Path, shard_out: &Path) -> Edges {
    let dir = tree.join("edges");
    std::fs::create_dir_all(&dir).unwrap();
    for ext in EXTS {
        let fifo = std::ffi::CString::new(dir.join(format!("fifo.{ext}")).to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path and a mode.
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0, "mkfifo");
        std::os::unix::fs::symlink("/dev/zero", dir.join(format!("zero.{ext}"))).unwrap();
        std::fs::create_dir(dir.join(format!("folder.{ext}"))).unwrap();
        // Sparse: past the default limit of the kind, on no disk.
        let limit: u64 = if ext == "toml" || ext == "json" {
            64 << 20
        } else {
            4 << 30
        };
        let f = std::fs::File::create(dir.join(format!("big.{ext}"))).unwrap();
        f.set_len(limit + 1).unwrap();
    }
    let run = |args: &[&str]| {
        let o = Command::new(bin).args(args).current_dir(&dir).output().unwrap();
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    };
    let fixed = format!("{ROOT}/models/fixed.toml");
    let mut a = vec!["run", &fixed];
    a.extend(FIXED);
    a.extend(["--out", "run-set"]);
    run(&a);
    run(&[
        "experiment",
        shard_experiment.to_str().unwrap(),
        "--quiet",
        "--out",
        "experiment-set",
    ]);
    let capture = format!("{ROOT}/tests/fixtures/presentmon/test_case_0.csv");
    run(&["replay", &capture, "--out", "replay-set"]);
    std::fs::write(dir.join("instance.toml"), super::text::INSTANCE).unwrap();
    let mut captures = Vec::new();
    for k in 0..3 {
        let name = format!("test_case_{k}.csv");
        let text = std::fs::read_to_string(Path::new(ROOT).join("tests/fixtures/presentmon").join(&name)).unwrap();
        captures.push((name, text.trim_start_matches('\u{feff}').to_string()));
    }
    Edges {
        sets: vec![
            ("run", dir.join("run-set")),
            ("experiment", dir.join("experiment-set")),
            ("replay", dir.join("replay-set")),
        ],
        dir,
        captures,
        shard_experiment: shard_experiment.to_path_buf(),
        shard_out: shard_out.to_path_buf(),
    }
}

/// Every file under `dir` (relative path, bytes); folders as `path/`.
pub fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(base: &Path, d: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        let Ok(entries) = std::fs::read_dir(d) else { return };
        for e in entries.flatten() {
            let p = e.path();
            let rel = p.strip_prefix(base).unwrap().display().to_string();
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                out.insert(format!("{rel}/"), Vec::new());
                walk(base, &p, out);
            } else {
                out.insert(rel, std::fs::read(&p).unwrap_or_default());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The first difference between two snapshots, if any.
pub fn changed(before: &BTreeMap<String, Vec<u8>>, after: &BTreeMap<String, Vec<u8>>) -> Option<String> {
    for (k, v) in after {
        match before.get(k) {
            None => return Some(format!("`{k}` added")),
            Some(b) if b != v => return Some(format!("`{k}` changed")),
            _ => {}
        }
    }
    before
        .keys()
        .find(|k| !after.contains_key(*k))
        .map(|k| format!("`{k}` removed"))
}

/// Keys whose values are of the process, not of the input.
const OF_THE_PROCESS: [&str; 6] = [
    "provenance",
    "wall_seconds",
    "build_seconds",
    "simulate_seconds",
    "events_per_second",
    "capture",
];

/// The first place where two JSON summaries differ: a number by more than
/// 1e-6 relative (1e-9 absolute), a missing key, another kind of value.
/// Strings (paths) and the process's own figures are not compared.
pub fn differ(a: &serde_json::Value, b: &serde_json::Value, path: &str) -> Option<String> {
    use serde_json::Value as V;
    match (a, b) {
        (V::Number(x), V::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            let close = (x - y).abs() <= 1e-9 + 1e-6 * x.abs().max(y.abs());
            (!close).then(|| format!("`{path}`: {x} against {y}"))
        }
        (V::Object(m), V::Object(n)) => m.iter().find_map(|(k, x)| {
            if OF_THE_PROCESS.contains(&k.as_str()) {
                return None;
            }
            match n.get(k) {
                Some(y) => differ(x, y, &format!("{path}.{k}")),
                None => Some(format!("`{path}.{k}` missing")),
            }
        }),
        (V::Array(p), V::Array(q)) if p.len() == q.len() => p
            .iter()
            .zip(q)
            .enumerate()
            .find_map(|(i, (x, y))| differ(x, y, &format!("{path}.{i}"))),
        (V::Array(_), V::Array(_)) => Some(format!("`{path}`: arrays of other lengths")),
        (V::String(_), V::String(_)) => None,
        _ if std::mem::discriminant(a) == std::mem::discriminant(b) => (a != b).then(|| format!("`{path}`")),
        _ => Some(format!("`{path}`: {a} against {b}")),
    }
}

/// One edge case.
pub fn case(rng: &mut Xoshiro256PlusPlus, n: usize, edges: &Edges) -> Case {
    match rng.random_range(0..4) {
        0 => bad_input(rng, edges),
        1 => capture(rng, n, edges),
        2 => inside_a_set(rng, n, edges),
        _ => full_stdout(rng, edges),
    }
}

fn strings(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

/// A reader of one kind of input file: its extension and its command with
/// `@` where the file goes.
fn readers() -> Vec<(&'static str, Vec<String>)> {
    let capture = format!("{ROOT}/tests/fixtures/presentmon/test_case_1.csv");
    let fixed = format!("{ROOT}/models/fixed.toml");
    let mut run = vec!["run".to_string(), "@".into()];
    run.extend(strings(&FIXED));
    run.push("--json".into());
    vec![
        ("toml", run),
        ("toml", strings(&["predict", "grid:16x16", "--device", "@", "--json"])),
        ("toml", strings(&["experiment", "@", "--quiet", "--out", "out"])),
        ("toml", strings(&["lod-select", "@", "--json"])),
        ("toml", strings(&["timeline", "@", "--frames", "2", "--out", "t.svg"])),
        ("toml", strings(&["isolate", "@", "--json"])),
        ("toml", strings(&["sortbuf", "scene:@", "--buffer", "4", "--json"])),
        ("csv", strings(&["calibrate", "@", "--out", "profile.toml", "--json"])),
        ("csv", strings(&["replay", "@", "--json"])),
        ("csv", strings(&["replay", &capture, "--compare", "@", "--json"])),
        ("csv", strings(&["sortbuf", "@", "--buffer", "4", "--json"])),
        ("obj", strings(&["vcache", "@", "--policy", "lru:16", "--json"])),
        ("idx", strings(&["vcache", "@", "--policy", "lru:16", "--json"])),
        (
            "idx",
            strings(&[
                "predict",
                "@",
                "--device",
                &format!("{ROOT}/models/devices/llvmpipe.toml"),
                "--json",
            ]),
        ),
        // `@` as the hardware file of a model (written as hw.toml).
        ("toml", {
            let mut a = strings(&["run", "hw.toml"]);
            a.extend(strings(&[
                "--set",
                "run.frames=2",
                "--set",
                "run.warmup_frames=0",
                "--set",
                "workload.scale=0.05",
                "--json",
            ]));
            a
        }),
        // `@` as a shard of a finished split.
        (
            "json",
            strings(&["experiment", "SHARDED", "--quiet", "--merge", "--out", "out"]),
        ),
        // A real file past --max-input-bytes (`@` stays a real model).
        ("limit", {
            let mut a = vec!["run".to_string(), fixed, "--max-input-bytes".into(), "64".into()];
            a.extend(strings(&FIXED));
            a.push("--json".into());
            a
        }),
    ]
}

/// An input file that is endless, huge, not a file, or past the limit.
fn bad_input(rng: &mut Xoshiro256PlusPlus, edges: &Edges) -> Case {
    let all = readers();
    let (ext, args) = all.choose(rng).unwrap().clone();
    if ext == "limit" {
        return Case {
            what: "edge: a model past --max-input-bytes".into(),
            blame: vec!["fixed.toml".into(), "max-input-bytes".into()],
            json: true,
            must_refuse: true,
            args,
            ..Case::default()
        };
    }
    let stand_ins = ["/dev/zero".to_string(), "/dev/urandom".to_string()]
        .into_iter()
        .chain(
            ["fifo", "zero", "folder", "big"]
                .iter()
                .map(|s| edges.dir.join(format!("{s}.{ext}")).display().to_string()),
        )
        .collect::<Vec<_>>();
    let bad = stand_ins.choose(rng).unwrap().clone();
    let name = Path::new(&bad).file_name().unwrap().to_string_lossy().to_string();
    let mut case = Case {
        what: format!("edge: {bad} as a .{ext} input"),
        blame: vec![name.clone(), bad.clone()],
        json: args.iter().any(|a| a == "--json"),
        must_refuse: true,
        ..Case::default()
    };
    let mut args: Vec<String> = args.into_iter().map(|a| a.replace('@', &bad)).collect();
    if args[1] == "hw.toml" {
        let city = std::fs::read_to_string(format!("{ROOT}/models/city-geforce3.toml")).unwrap();
        let text = city.replace("hardware = \"hardware/geforce3.toml\"", &format!("hardware = {bad:?}"));
        assert_ne!(text, city, "city-geforce3.toml names its hardware file");
        case.files.push(("hw.toml".into(), text));
        case.blame.push("hardware".into());
    }
    if args[1] == "SHARDED" {
        args[1] = edges.shard_experiment.display().to_string();
        case.copy.push((edges.shard_out.clone(), "out".into()));
        let k = rng.random_range(1..=3);
        case.links
            .push((PathBuf::from(&bad), format!("out/shards/shard-{k}-of-3.json")));
        case.blame.push(format!("shard-{k}-of-3.json"));
        case.json = false;
    }
    case.args = args;
    case
}

/// The columns of a capture's header, and its rows.
fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn join(header: &[String], rows: &[Vec<String>]) -> String {
    let mut s = header.join(",") + "\n";
    for r in rows {
        s.push_str(&r.join(","));
        s.push('\n');
    }
    s
}

/// A capture damaged in a way the replay must question, or changed in a
/// way that must not change its replay.
fn capture(rng: &mut Xoshiro256PlusPlus, n: usize, edges: &Edges) -> Case {
    let (from, text) = edges.captures.choose(rng).unwrap();
    let (header, mut rows) = table(text);
    let name = format!("capture-{n}.csv");
    let reference = format!("reference-{n}.csv");
    let stamps: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| h.ends_with("QPC"))
        .map(|(i, _)| i)
        .collect();
    let shift = |rows: &mut Vec<Vec<String>>, by: i128| {
        for r in rows.iter_mut() {
            for &c in &stamps {
                if let Some(v) = r.get(c).and_then(|v| v.parse::<i128>().ok()) {
                    r[c] = (v + by).to_string();
                }
            }
        }
    };
    let max_stamp = rows
        .iter()
        .flat_map(|r| stamps.iter().filter_map(|&c| r.get(c)?.parse::<i128>().ok()))
        .max()
        .unwrap_or(0);
    let replay = |file: &str| strings(&["replay", file, "--json"]);
    let mut case = Case {
        args: replay(&name),
        blame: vec![name.clone()],
        json: true,
        allow_null: vec!["torn_per_second"],
        ..Case::default()
    };
    let (body, what) = match rng.random_range(0..5) {
        0 => {
            let c = rng.random_range(0..header.len());
            let mut h = header.clone();
            h.push(header[c].clone());
            for r in rows.iter_mut() {
                let v = r.get(c).cloned().unwrap_or_default();
                r.push(v);
            }
            // A column the replay reads is refused; one it does not read
            // changes nothing.
            case.blame.push(format!("`{}` twice", header[c]));
            case.files.push((reference.clone(), text.clone()));
            case.same_as = Some(replay(&reference));
            (
                join(&h, &rows).into_bytes(),
                format!("column {} named twice", header[c]),
            )
        }
        1 => {
            let doubled: Vec<Vec<String>> = rows.iter().flat_map(|r| [r.clone(), r.clone()]).collect();
            case.must_refuse = true;
            (join(&header, &doubled).into_bytes(), "every row twice".into())
        }
        2 if !stamps.is_empty() => {
            let first = rows
                .iter()
                .filter_map(|r| r.get(stamps[0])?.parse::<i128>().ok())
                .min()
                .unwrap_or(0);
            shift(&mut rows, -first - rng.random_range(1..1_000_000_000i128));
            case.must_refuse = true;
            case.blame.push("negative".into());
            (join(&header, &rows).into_bytes(), "stamps before zero".into())
        }
        3 if !stamps.is_empty() => {
            // Up to the largest stamp an i64 holds.
            let room = i64::MAX as i128 - max_stamp;
            let by = rng.random_range(room / 4..=room);
            case.files.push((reference.clone(), text.clone()));
            case.same_as = Some(replay(&reference));
            shift(&mut rows, by);
            (join(&header, &rows).into_bytes(), format!("stamps shifted by {by}"))
        }
        _ => {
            let big = rng.random_bool(0.5);
            let mut bytes = if big { vec![0xfe, 0xff] } else { vec![0xff, 0xfe] };
            for u in text.encode_utf16() {
                bytes.extend(if big { u.to_be_bytes() } else { u.to_le_bytes() });
            }
            case.files.push((reference.clone(), text.clone()));
            case.same_as = Some(replay(&reference));
            (bytes, format!("UTF-16 {}", if big { "BE" } else { "LE" }))
        }
    };
    // The capture's bytes go in through a file written here (UTF-16 is
    // not text `files` can hold).
    let dir = edges.dir.join(format!("capture-{n}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(&name), body).unwrap();
    case.copy.push((dir.clone(), ".".into()));
    case.cleanup.push(dir.join(&name));
    case.what = format!("edge: {from}: {what}");
    case
}

/// A command that writes a file or a folder inside another command's
/// result set.
fn inside_a_set(rng: &mut Xoshiro256PlusPlus, n: usize, edges: &Edges) -> Case {
    let (kind, set) = edges.sets.choose(rng).unwrap();
    let existing: Vec<String> = snapshot(set).keys().filter(|k| !k.ends_with('/')).cloned().collect();
    // A name already there (the set's own files, its marker) or a new one.
    let leaf = |rng: &mut Xoshiro256PlusPlus, ext: &str| -> String {
        if rng.random_bool(0.5) {
            let name = existing.choose(rng).unwrap();
            if ext == "svg" || ext == "png" {
                // A picture's name must end as one: past that check.
                let stem = name.rsplit_once('.').map_or(name.as_str(), |(stem, _)| stem);
                format!(
                    "{}.{ext}",
                    if stem.ends_with('/') || stem.is_empty() {
                        "new"
                    } else {
                        stem
                    }
                )
            } else {
                name.clone()
            }
        } else {
            format!("new-{n}.{ext}")
        }
    };
    let form = rng.random_range(0..4);
    let place = |p: String| -> String {
        match form {
            0 => format!("set/{p}"),
            1 => format!("set/./{p}"),
            2 => format!("set/../set/{p}"),
            _ => format!("ABS/set/{p}"),
        }
    };
    let fixed = format!("{ROOT}/models/fixed.toml");
    let csv = format!("{ROOT}/docs/measurements/llvmpipe-mesa-22.3.6-passes.csv");
    let capture = format!("{ROOT}/tests/fixtures/presentmon/test_case_1.csv");
    let walk = format!("{ROOT}/models/walkthrough-city.toml");
    let mut args: Vec<String> = match rng.random_range(0..9) {
        0 => {
            let mut a = strings(&["run", &fixed]);
            a.extend(strings(&FIXED));
            a.extend(["--trace".into(), place(leaf(rng, "json"))]);
            a
        }
        1 => {
            let mut a = strings(&["run", &fixed]);
            a.extend(strings(&FIXED));
            a.extend(["--out".into(), place(format!("inner-{n}"))]);
            a
        }
        2 => strings(&["timeline", &fixed, "--frames", "2", "--out", &place(leaf(rng, "svg"))]),
        3 => strings(&["calibrate", &csv, "--out", &place(leaf(rng, "toml"))]),
        4 => strings(&[
            "calibrate",
            &csv,
            "--out",
            "p.toml",
            "--report",
            &place(leaf(rng, "md")),
        ]),
        5 => strings(&["replay", &capture, "--out", &place(format!("inner-{n}"))]),
        6 => strings(&["replay", &capture, "--report", &place(format!("inner-{n}"))]),
        7 => strings(&[
            "experiment",
            edges.shard_experiment.to_str().unwrap(),
            "--quiet",
            "--out",
            &place(format!("inner-{n}")),
        ]),
        _ => strings(&[
            "perceived-speed",
            &walk,
            "--set",
            "run.frames=40",
            "--out",
            &place(leaf(rng, "png")),
        ]),
    };
    Case {
        what: format!("edge: into a {kind} set: {}", args.join(" ")),
        // ABS is filled in where the case runs (its folder is made then).
        args: std::mem::take(&mut args),
        blame: vec!["inside".into()],
        must_refuse: true,
        copy: vec![(set.clone(), "set".into())],
        guard: Some("set".into()),
        ..Case::default()
    }
}

/// A command that prints, with standard output on a full disk.
fn full_stdout(rng: &mut Xoshiro256PlusPlus, edges: &Edges) -> Case {
    let fixed = format!("{ROOT}/models/fixed.toml");
    let capture = format!("{ROOT}/tests/fixtures/presentmon/test_case_1.csv");
    let mut run = strings(&["run", &fixed]);
    run.extend(strings(&FIXED));
    let mut run_json = run.clone();
    run_json.push("--json".into());
    let mut trace = run.clone();
    trace.extend(strings(&["--trace", "-"]));
    let instance = edges.dir.join("instance.toml").display().to_string();
    let commands: Vec<Vec<String>> = vec![
        run,
        run_json,
        trace,
        strings(&["vcache", "grid:8x8", "--policy", "fifo:8", "--json"]),
        strings(&["vcache", "grid:8x8", "--policy", "fifo:8"]),
        strings(&["replay", &capture, "--json"]),
        strings(&["replay", &capture]),
        strings(&["lod-select", &instance, "--json"]),
        strings(&[
            "predict",
            "grid:16x16",
            "--device",
            &format!("{ROOT}/models/devices/llvmpipe.toml"),
            "--json",
        ]),
        strings(&[
            "sortbuf",
            "lru-worst:3",
            "--buffer",
            "10",
            "--strategy",
            "lru",
            "--json",
        ]),
        strings(&[
            "isolate",
            &fixed,
            "--set",
            "run.frames=20",
            "--set",
            "run.warmup_frames=2",
        ]),
        strings(&["experiment", edges.shard_experiment.to_str().unwrap(), "--out", "out"]),
        strings(&["man"]),
        strings(&["completions", "bash"]),
        strings(&["--help"]),
        strings(&["run", "--help"]),
        strings(&["--version"]),
    ];
    let args = commands.choose(rng).unwrap().clone();
    Case {
        what: format!("edge: standard output full: {}", args.join(" ")),
        args,
        blame: vec!["standard output".into(), "No space left".into()],
        must_refuse: true,
        stdout_full: true,
        ..Case::default()
    }
}
