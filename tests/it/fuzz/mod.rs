//! A seeded fuzz test of every input a user gives: model files, `--set`
//! values, mesh specs with cache policies, and experiment files (leaf values
//! changed, here), and text-level damage to every kind of file rendersim
//! reads, shard files and measurement CSVs included ([`text`]), and
//! mutations at the edges of the file system and the process: endless,
//! huge and special input files, questionable captures, outputs inside
//! another command's result set, a full standard output ([`edges`]).
//!
//! Each case runs the real binary under a memory cap (RLIMIT_AS) and a hang
//! guard, and must end in one of two ways:
//! - success, with a JSON summary in which no number is missing (`null`
//!   only where a statistic is empty: an object with `count: 0`);
//! - a clean error: exit status 2, an `error:` line, no panic, and a message
//!   that names the key, the option or the file at fault.
//!
//! Anything else (a panic, an abort such as "memory allocation failed", a
//! signal, a hang, a null number) fails the test, and the case is printed
//! as a command line to paste into `tests/fuzz-regressions.txt`, whose cases
//! run first on every run. `RENDERSIM_FUZZ_CASES` (default 2,000 leaf-value
//! cases), `RENDERSIM_FUZZ_TEXT_CASES` (default 1,000 text cases),
//! `RENDERSIM_FUZZ_EDGE_CASES` (default 400 edge cases) and
//! `RENDERSIM_FUZZ_SEED` (default 1) choose the cases; the counts are
//! printed, by command and by verdict. The hang guard (60 s, against runs that normally take well under
//! a second) only catches hangs; it is not a speed check.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng, seq::IndexedRandom};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

mod edges;
mod text;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Address-space cap per case.
const MEMORY_CAP: u64 = 3 << 30;
/// Hang guard per case.
const HANG_GUARD: Duration = Duration::from_secs(60);

/// One fuzz case: the arguments after `rendersim`, files it needs written
/// first (name, text), and the words one of which a clean error must contain.
#[derive(Debug, Clone, Default)]
struct Case {
    /// What was mutated (for a case whose input is a written file).
    what: String,
    args: Vec<String>,
    files: Vec<(String, String)>,
    blame: Vec<String>,
    /// Whether success must print a complete JSON summary.
    json: bool,
    /// Keys whose value may be `null` in that summary (an option not asked for).
    allow_null: Vec<&'static str>,
    /// Folders copied into the case's folder first (from, to).
    copy: Vec<(PathBuf, String)>,
    /// Files removed after the case (written outside the case's folder).
    cleanup: Vec<PathBuf>,
    /// The input is wrong whatever the values (a table written as an
    /// array): a result is a failure, only a clean error passes.
    must_refuse: bool,
    /// Links made in the case's folder after the copies and files (target,
    /// name): a name that stands for a device or a FIFO.
    links: Vec<(PathBuf, String)>,
    /// Standard output is `/dev/full` (a full disk).
    stdout_full: bool,
    /// A folder of the case's (another command's result set) that must be
    /// the same, byte for byte, after the case.
    guard: Option<String>,
    /// On success, the same command on an equivalent input (a capture's
    /// stamps shifted, another encoding): every number of the two JSON
    /// summaries must agree to 1e-6, relative.
    same_as: Option<Vec<String>>,
}

impl Case {
    fn command_line(&self) -> String {
        let mut s = String::from("rendersim");
        for a in &self.args {
            s.push(' ');
            if a.contains(|c: char| c.is_whitespace() || "\"'{}[]$".contains(c)) {
                s.push_str(&format!("'{a}'"));
            } else {
                s.push_str(a);
            }
        }
        s
    }
}

/// Base models, each with `--set`s that keep one run small, and the keys
/// that those bound (a mutation of such a key drops its bound).
fn bases() -> Vec<(&'static str, Vec<&'static str>)> {
    // Systems with `run.max_memory` get 1 GiB (under the 3 GiB cap), so a
    // long but valid run is refused by its own estimate, not by the cap; and
    // `run.max_events`, so a valid but huge amount of work asked for (a
    // million copies of a mesh) stops at a bound instead of running for hours.
    const MEM: &str = "run.max_memory=\"1GiB\"";
    const EVENTS: &str = "run.max_events=3000000";
    vec![
        (
            "models/default.toml",
            vec!["run.frames=3", "run.warmup_frames=0", MEM, EVENTS],
        ),
        (
            "models/fixed.toml",
            vec!["run.frames=20", "run.warmup_frames=2", MEM, EVENTS],
        ),
        (
            "models/one-mesh.toml",
            vec!["run.frames=2", "run.warmup_frames=0", MEM, EVENTS],
        ),
        (
            "models/city.toml",
            vec![
                "run.frames=2",
                "run.warmup_frames=0",
                "workload.scale=0.05",
                MEM,
                EVENTS,
            ],
        ),
        (
            "models/single-view.toml",
            vec!["run.frames=30", "run.warmup_frames=2", MEM, EVENTS],
        ),
        ("models/mfr-cluster.toml", vec!["run.events=40", MEM, EVENTS]),
        ("models/mfr-migration.toml", vec!["run.events=20", MEM, EVENTS]),
        ("models/vr-warp.toml", vec!["run.events=40", MEM, EVENTS]),
        ("models/vr-naive.toml", vec!["run.events=40", MEM, EVENTS]),
        ("models/pixelflow-20.toml", vec!["primitives=2000"]),
        ("models/present.toml", vec!["run.frames=50", EVENTS]),
    ]
}

/// Every leaf key of a table as a dotted path (array elements by index).
fn leaves(prefix: &str, v: &toml::Value, out: &mut Vec<(String, toml::Value)>) {
    match v {
        toml::Value::Table(t) => {
            for (k, v) in t {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                leaves(&p, v, out);
            }
        }
        toml::Value::Array(a) if !a.is_empty() => {
            for (i, v) in a.iter().enumerate() {
                leaves(&format!("{prefix}.{i}"), v, out);
            }
        }
        _ => out.push((prefix.to_string(), v.clone())),
    }
}

/// Values that break things: zero, negative, huge, tiny, non-finite, wrong
/// types and units, and sizes far past any limit.
const NASTY: &[&str] = &[
    "0",
    "-1",
    "1",
    "4294967295",
    "9223372036854775807",
    "-9223372036854775808",
    "1e308",
    "-1e308",
    "1e-308",
    "-0.0",
    "nan",
    "inf",
    "-inf",
    "\"\"",
    "\"abc\"",
    "\"0ms\"",
    "\"-5ms\"",
    "\"1ps\"",
    "\"1e300s\"",
    "\"5000000s\"",
    "\"18446744073709551615ps\"",
    "\"0Hz\"",
    "\"1e12Hz\"",
    "\"0.001Hz\"",
    "\"60Hz\"",
    "\"5ms\"",
    "\"0B/s\"",
    "\"1B/s\"",
    "\"1e30GB/s\"",
    "\"7 parsecs\"",
    "true",
    "[]",
    "[1, 2]",
    "{}",
    "{ kind = \"lognormal\", median = \"0ms\", sigma = 1e308 }",
    "{ kind = \"uniform\", min = \"5ms\", max = \"1ms\" }",
    "\"fifo:0\"",
    "\"lru:4294967295\"",
    "\"direct:4294967295,1\"",
    "\"grid:100000x100000\"",
    "\"grid:0x0\"",
    "\"random:0:0:1\"",
];

/// Scales the number at the start of `v` (keeping its unit) by `f`.
fn scaled(v: &toml::Value, f: f64) -> Option<String> {
    match v {
        toml::Value::Integer(i) => Some(format!("{}", (*i as f64 * f).round() as i128)),
        toml::Value::Float(x) => Some(format!("{:e}", x * f)),
        toml::Value::String(s) => {
            let end = s
                .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
                .unwrap_or(s.len());
            let n: f64 = s[..end].parse().ok()?;
            Some(format!("\"{:e}{}\"", n * f, &s[end..]))
        }
        _ => None,
    }
}

/// A base model drawn at random, its text and table, and one of its leaf
/// keys with its value.
#[allow(clippy::type_complexity)]
fn pick_base(
    rng: &mut Xoshiro256PlusPlus,
) -> (
    &'static str,
    Vec<&'static str>,
    String,
    toml::Value,
    String,
    toml::Value,
) {
    let all = bases();
    let (file, bounds) = all.choose(rng).unwrap().clone();
    let text = std::fs::read_to_string(Path::new(ROOT).join(file)).unwrap();
    let table: toml::Value = toml::from_str(&text).unwrap();
    let mut keys = Vec::new();
    leaves("", &table, &mut keys);
    let (key, old) = keys.choose(rng).unwrap().clone();
    (file, bounds, text, table, key, old)
}

fn model_case(rng: &mut Xoshiro256PlusPlus, n: usize) -> Case {
    let (file, bounds, text, table, key, old) = pick_base(rng);
    let value = match rng.random_range(0..10) {
        0..=5 => NASTY.choose(rng).unwrap().to_string(),
        _ => {
            let f = *[0.0, -1.0, 1e-9, 1e6, 1e12, 1e18].choose(rng).unwrap();
            scaled(&old, f).unwrap_or_else(|| NASTY.choose(rng).unwrap().to_string())
        }
    };
    let mut args = vec!["run".to_string()];
    let mut files = Vec::new();
    let mut blame = vec![key.clone(), key.rsplit('.').next().unwrap().to_string()];
    let mut what = String::new();
    let mut must_refuse = false;
    match rng.random_range(0..5) {
        // The value in a model file (written as TOML).
        0 => {
            let name = format!("case-{n}.toml");
            let mut t = table.clone();
            let parsed = format!("v = {value}")
                .parse::<toml::Table>()
                .ok()
                .and_then(|mut t| t.remove("v"))
                .unwrap_or(toml::Value::String(value.clone()));
            if rendersim::config::set_dotted(t.as_table_mut().unwrap(), &key, parsed).is_err() {
                return model_case(rng, n);
            }
            files.push((name.clone(), toml::to_string(&t).unwrap()));
            args.push(name.clone());
            blame.push(name);
            what = format!("{file} with {key} = {value} in the file");
        }
        // A misspelt key in a model file.
        1 => {
            let name = format!("case-{n}.toml");
            let typo = format!("{key}x");
            let line = format!("{} = 1", typo.rsplit('.').next().unwrap());
            // Append as a new key of the same table.
            let table_path: Vec<&str> = typo.split('.').collect();
            let section = table_path[..table_path.len() - 1].join(".");
            let body = if section.is_empty() || section.chars().any(|c| c.is_ascii_digit()) {
                format!("{line}\n{text}")
            } else {
                format!("{text}\n[{section}]\n{line}\n")
            };
            files.push((name.clone(), body));
            args.push(name.clone());
            blame.push(name);
            what = format!("{file} with the misspelt key {typo}");
            blame.push(typo);
        }
        // The key's table written as an array of its values, as --set
        // takes it (serde once read such arrays field by position).
        4 if key.contains('.') && !key.split('.').any(|p| p.parse::<usize>().is_ok()) => {
            let parent = key.rsplit_once('.').unwrap().0;
            let mut t = table.clone();
            let mut at = t.as_table_mut().unwrap();
            for part in parent.split('.') {
                at = at.get_mut(part).and_then(|v| v.as_table_mut()).unwrap();
            }
            let values: Vec<String> = at
                .values()
                .filter(|v| !v.is_table() && !v.is_array())
                .map(|v| v.to_string())
                .collect();
            args.push(Path::new(ROOT).join(file).display().to_string());
            args.push("--set".into());
            args.push(format!("{parent}=[{}]", values.join(", ")));
            blame.push(parent.to_string());
            must_refuse = true;
            what = format!("{file} with its table {parent} written as an array");
        }
        // The value from --set.
        _ => {
            args.push(Path::new(ROOT).join(file).display().to_string());
            args.push("--set".into());
            args.push(format!("{key}={value}"));
            blame.push("--set".into());
            blame.push(file.rsplit('/').next().unwrap().to_string());
        }
    }
    for b in bounds {
        if !b.starts_with(&format!("{key}=")) {
            args.push("--set".into());
            args.push(b.to_string());
        }
    }
    args.push("--json".into());
    Case {
        what,
        args,
        files,
        blame,
        json: true,
        allow_null: vec![],
        copy: vec![],
        cleanup: vec![],
        must_refuse,
        ..Case::default()
    }
}

fn mesh_case(rng: &mut Xoshiro256PlusPlus) -> Case {
    let num = |rng: &mut Xoshiro256PlusPlus| -> String {
        [
            "0",
            "1",
            "2",
            "3",
            "17",
            "64",
            "255",
            "4294967295",
            "18446744073709551616",
            "-1",
            "1.5",
            "",
            "x",
        ]
        .choose(rng)
        .unwrap()
        .to_string()
    };
    let mesh = match rng.random_range(0..7) {
        0 => format!("grid:{}x{}", num(rng), num(rng)),
        1 => format!("grid:{}x{}:shuffled:{}", num(rng), num(rng), num(rng)),
        2 => format!("grid:{}x{}:optimized", num(rng), num(rng)),
        3 => format!("grid:{}x{}:local:{}:{}", num(rng), num(rng), num(rng), num(rng)),
        4 => format!("strip:{}x{}", num(rng), num(rng)),
        5 => format!("random:{}:{}:{}", num(rng), num(rng), num(rng)),
        _ => [
            "grid",
            "grid:",
            "grid:8",
            "nofile.obj",
            "nofile.idx",
            "::",
            "grid:8x8:bogus",
        ]
        .choose(rng)
        .unwrap()
        .to_string(),
    };
    let policy = match rng.random_range(0..9) {
        0 => "none".to_string(),
        1 => format!("fifo:{}", num(rng)),
        2 => format!("lru:{}", num(rng)),
        3 => format!("meshopt:{},{},{}", num(rng), num(rng), num(rng)),
        4 => format!("batch:{},{}", num(rng), num(rng)),
        5 => format!("direct:{},{}", num(rng), num(rng)),
        6 => "lavapipe".to_string(),
        7 => format!("lavapipe:{}", num(rng)),
        _ => ["", "fifo", "fifo:", "lru:8:8", "unknown:3"]
            .choose(rng)
            .unwrap()
            .to_string(),
    };
    let blame = vec![mesh.clone(), policy.clone(), "--policy".into(), "mesh".into()];
    Case {
        what: String::new(),
        args: vec!["vcache".into(), mesh, "--policy".into(), policy, "--json".into()],
        files: vec![],
        blame,
        json: true,
        allow_null: vec![],
        copy: vec![],
        cleanup: vec![],
        must_refuse: false,
        ..Case::default()
    }
}

fn experiment_case(rng: &mut Xoshiro256PlusPlus, n: usize) -> Case {
    let (file, bounds, _, _, key, old) = pick_base(rng);
    let pick = |rng: &mut Xoshiro256PlusPlus| -> String {
        if rng.random_bool(0.5) {
            NASTY.choose(rng).unwrap().to_string()
        } else {
            let mut t = toml::Table::new();
            t.insert("v".into(), old.clone());
            toml::to_string(&t)
                .ok()
                .and_then(|s| s.strip_prefix("v = ").map(|s| s.trim().to_string()))
                .unwrap_or_else(|| "1".into())
        }
    };
    let replications = *["1", "2", "0", "-3", "100000000", "1.5", "\"two\""]
        .choose(rng)
        .unwrap();
    let metric = *[
        "wall_seconds",
        "metrics.frame_time_ms.mean",
        "metrics.event_latency_ms.fast.mean",
        "metrics.latency_ms",
        "metrics.nothing",
        "",
        "metrics..x",
    ]
    .choose(rng)
    .unwrap();
    let mut set = String::new();
    for b in bounds {
        let (k, v) = b.split_once('=').unwrap();
        if k != key {
            set.push_str(&format!("\"{k}\" = {v}\n"));
        }
    }
    let sweep = match rng.random_range(0..3) {
        0 => format!("[[sweep]]\nkey = \"{key}\"\nvalues = [{}, {}]\n", pick(rng), pick(rng)),
        1 => format!(
            "[[sweep]]\nkey = \"{key}\"\nrange = {{ from = 0, to = {}, steps = 3 }}\n",
            pick(rng)
        ),
        _ => {
            set.push_str(&format!("\"{key}\" = {}\n", pick(rng)));
            String::new()
        }
    };
    let check = match rng.random_range(0..3) {
        0 => format!("[[check]]\npath = \"{metric}\"\nexpect = 1.0\ntolerance = 0.5\n"),
        _ => String::new(),
    };
    let name = format!("exp-{n}.toml");
    let model = Path::new(ROOT).join(file).display().to_string();
    let body = format!(
        "name = \"fuzz-{n}\"\nmodel = \"{model}\"\nreplications = {replications}\n[set]\n{set}\n{sweep}\n[[metric]]\npath = \"{metric}\"\n{check}"
    );
    let blame = vec![
        name.clone(),
        key.clone(),
        key.rsplit('.').next().unwrap().to_string(),
        metric.to_string(),
    ];
    Case {
        what: body.clone(),
        args: vec![
            "experiment".into(),
            name.clone(),
            "--quiet".into(),
            "--out".into(),
            format!("out-{n}"),
        ],
        files: vec![(name, body)],
        blame,
        json: false,
        allow_null: vec![],
        copy: vec![],
        cleanup: vec![],
        must_refuse: false,
        ..Case::default()
    }
}

/// How a case ended, when it ended wrongly.
fn judge(case: &Case, dir: &Path) -> Result<&'static str, String> {
    for (from, to) in &case.copy {
        copy_dir(from, &dir.join(to));
    }
    for (name, text) in &case.files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    for (target, name) in &case.links {
        let link = dir.join(name);
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(target, &link).unwrap();
    }
    let before = case.guard.as_ref().map(|g| edges::snapshot(&dir.join(g)));
    let verdict = run_case(case, dir, &case.args)?;
    if let (Some(g), Some(before)) = (&case.guard, before)
        && let Some(change) = edges::changed(&before, &edges::snapshot(&dir.join(g)))
    {
        return Err(format!("wrote inside another command's result set `{g}`: {change}"));
    }
    if let (Some(reference), ("ok", Some(out))) = (&case.same_as, &verdict) {
        let (_, Some(expected)) = run_case(case, dir, reference)? else {
            return Err("the reference command printed no JSON".into());
        };
        if let Some(diff) = edges::differ(&expected, out, "") {
            return Err(format!(
                "differs from the same input as written before the change: {diff}"
            ));
        }
    }
    Ok(verdict.0)
}

/// Runs `args` as `case` says (limits, standard output) in `dir`; on
/// success with a JSON summary, returns it too.
fn run_case(case: &Case, dir: &Path, args: &[String]) -> Result<(&'static str, Option<serde_json::Value>), String> {
    // `ABS/` stands for the case's own folder, absolute.
    let abs = format!("{}/", dir.display());
    let args: Vec<String> = args.iter().map(|a| a.replace("ABS/", &abs)).collect();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rendersim"));
    cmd.args(&args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if case.stdout_full {
        cmd.stdout(std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap());
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        // SAFETY: only an async-signal-safe setrlimit between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                let lim = libc::rlimit {
                    rlim_cur: MEMORY_CAP as libc::rlim_t,
                    rlim_max: MEMORY_CAP as libc::rlim_t,
                };
                libc::setrlimit(libc::RLIMIT_AS, &lim);
                Ok(())
            });
        }
    }
    let mut child = cmd.spawn().unwrap();
    let mut out_pipe: Box<dyn Read + Send> = match child.stdout.take() {
        Some(p) => Box::new(p),
        None => Box::new(std::io::empty()),
    };
    let mut err_pipe = child.stderr.take().unwrap();
    let out_reader = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = out_pipe.read_to_end(&mut v);
        v
    });
    let err_reader = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = err_pipe.read_to_end(&mut v);
        v
    });
    let started = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if started.elapsed() > HANG_GUARD {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("no end after {} s (hang guard)", HANG_GUARD.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let stdout = String::from_utf8_lossy(&out_reader.join().unwrap()).to_string();
    let stderr = String::from_utf8_lossy(&err_reader.join().unwrap()).to_string();
    let tail = |s: &str| {
        s.chars()
            .rev()
            .take(600)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect::<String>()
    };
    if let Some(at) = stderr.find("panicked").or_else(|| stderr.find("memory allocation of")) {
        let from = stderr[..at].rfind('\n').map_or(0, |i| i + 1);
        let what: String = stderr[from..].lines().take(2).collect::<Vec<_>>().join(" / ");
        return Err(format!("panic or abort: {what}"));
    }
    match status.code() {
        Some(0) if case.must_refuse => Err("taken, though the input is wrong whatever its values".into()),
        Some(0) => {
            if !case.json {
                return Ok(("ok", None));
            }
            let v: serde_json::Value =
                serde_json::from_str(&stdout).map_err(|e| format!("success without a JSON summary ({e})"))?;
            if let Some(path) = null_number(&v, "", &case.allow_null) {
                return Err(format!("null where a number belongs: `{path}`"));
            }
            Ok(("ok", Some(v)))
        }
        Some(2) => {
            let first = stderr.lines().find(|l| l.starts_with("error:"));
            let Some(_) = first else {
                return Err(format!("exit 2 without an `error:` line: {}", tail(&stderr)));
            };
            let lower = stderr.to_lowercase();
            if case
                .blame
                .iter()
                .any(|b| !b.is_empty() && lower.contains(&b.to_lowercase()))
            {
                Ok(("clean error", None))
            } else {
                Err(format!("the error names none of {:?}: {}", case.blame, tail(&stderr)))
            }
        }
        // Failed checks of an experiment (its report says which).
        Some(1) if case.args[0] == "experiment" => Ok(("failed check", None)),
        Some(c) => Err(format!("exit status {c}: {}", tail(&stderr))),
        None => Err(format!("ended by a signal: {}", tail(&stderr))),
    }
}

/// The path of a `null` that is not an empty statistic (an object with
/// `count: 0`) nor under a key of `allow`, if any.
fn null_number(v: &serde_json::Value, path: &str, allow: &[&str]) -> Option<String> {
    match v {
        serde_json::Value::Null => Some(path.to_string()),
        serde_json::Value::Object(m) => {
            let empty_stat = m.get("count").and_then(|c| c.as_u64()) == Some(0);
            m.iter().find_map(|(k, x)| {
                if (empty_stat && x.is_null()) || allow.contains(&k.as_str()) {
                    None
                } else {
                    null_number(x, &format!("{path}.{k}"), allow)
                }
            })
        }
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| null_number(x, &format!("{path}.{i}"), allow)),
        _ => None,
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// Where a case comes from: the list made up front (regressions and
/// leaf-value cases), or made where it runs from its own stream.
enum Job {
    Listed,
    Text(usize),
    Edge(usize),
}

/// Regression cases: one command line per line (after `rendersim`), split on
/// spaces, with single quotes around arguments that hold spaces.
fn regressions() -> Vec<Case> {
    let text = std::fs::read_to_string(Path::new(ROOT).join("tests/fuzz-regressions.txt")).unwrap_or_default();
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| {
            let mut args = Vec::new();
            let mut cur = String::new();
            let mut quoted = false;
            for c in l.strip_prefix("rendersim ").unwrap_or(l).chars() {
                match c {
                    '\'' => quoted = !quoted,
                    ' ' if !quoted => {
                        if !cur.is_empty() {
                            args.push(std::mem::take(&mut cur));
                        }
                    }
                    _ => cur.push(c),
                }
            }
            if !cur.is_empty() {
                args.push(cur);
            }
            let args: Vec<String> = args.into_iter().map(|a| a.replace("$ROOT", ROOT)).collect();
            // A clean error must name one of the arguments' words.
            let blame = args
                .iter()
                .flat_map(|a| {
                    let mut v = vec![a.clone()];
                    if let Some((k, _)) = a.split_once('=') {
                        v.push(k.to_string());
                        v.push(k.rsplit('.').next().unwrap_or(k).to_string());
                    }
                    v
                })
                .collect();
            Case {
                what: String::new(),
                json: args.iter().any(|a| a == "--json"),
                args,
                files: vec![],
                blame,
                allow_null: vec![],
                copy: vec![],
                cleanup: vec![],
                must_refuse: false,
                ..Case::default()
            }
        })
        .collect()
}

#[test]
fn every_input_ends_in_a_result_or_a_clean_error() {
    let seed: u64 = std::env::var("RENDERSIM_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let count: usize = std::env::var("RENDERSIM_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let text_count: usize = std::env::var("RENDERSIM_FUZZ_TEXT_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let edge_count: usize = std::env::var("RENDERSIM_FUZZ_EDGE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(400);
    let dir = tempfile::tempdir().unwrap();
    let bin = Path::new(env!("CARGO_BIN_EXE_rendersim"));
    let tree = text::prepare(dir.path(), bin);
    let edges = edges::prepare(&tree.root, bin, &tree.shard_experiment, &tree.shard_out);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut cases = regressions();
    let fixed = cases.len();
    for n in 0..count {
        cases.push(match rng.random_range(0..10) {
            0..=5 => model_case(&mut rng, n),
            6..=7 => mesh_case(&mut rng),
            _ => experiment_case(&mut rng, n),
        });
    }
    // Text cases are made where they run, each from its own stream (seed,
    // n): their inputs (5 MB strings among them) are never all in memory.
    let jobs: Vec<Job> = (0..cases.len())
        .map(|_| Job::Listed)
        .chain((0..text_count).map(Job::Text))
        .chain((0..edge_count).map(Job::Edge))
        .collect();
    let counts: Mutex<std::collections::BTreeMap<String, usize>> = Mutex::default();
    let failures: Mutex<Vec<(String, String)>> = Mutex::default();
    let slowest: Mutex<Vec<(f64, String)>> = Mutex::default();
    let started = Instant::now();
    jobs.par_iter().enumerate().for_each(|(i, job)| {
        let made;
        let case = match job {
            Job::Listed => &cases[i],
            Job::Text(n) => {
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ *n as u64);
                made = text::case(&mut rng, *n, &tree);
                &made
            }
            Job::Edge(n) => {
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed.wrapping_mul(0xbf58_476d_1ce4_e5b9) ^ *n as u64);
                made = edges::case(&mut rng, *n, &edges);
                &made
            }
        };
        // Each case in a folder of its own (experiments write there).
        let d: PathBuf = dir.path().join(format!("c{i}"));
        std::fs::create_dir(&d).unwrap();
        // Counted by command (an experiment's mode apart) and input kind.
        let mode = ["--merge", "--slurm", "--shard"]
            .iter()
            .find(|m| case.args.iter().any(|a| a == *m))
            .map(|m| format!(" {m}"))
            .unwrap_or_default();
        let kind = format!(
            "{}{mode}{} ",
            case.args[0],
            if case.what.starts_with("text:") {
                " (text)"
            } else if case.what.starts_with("edge:") {
                " (edge)"
            } else {
                ""
            }
        );
        let t0 = Instant::now();
        let verdict = judge(case, &d);
        slowest
            .lock()
            .unwrap()
            .push((t0.elapsed().as_secs_f64(), case.command_line()));
        match verdict {
            Ok(how) => *counts.lock().unwrap().entry(kind + how).or_default() += 1,
            Err(why) => {
                *counts.lock().unwrap().entry(kind + "FAILED").or_default() += 1;
                let line = if case.what.is_empty() {
                    case.command_line()
                } else {
                    format!(
                        "{}\n        input: {}",
                        case.command_line(),
                        case.what.replace('\n', "\n               ")
                    )
                };
                failures.lock().unwrap().push((line, why));
            }
        }
        let _ = std::fs::remove_dir_all(&d);
        for p in &case.cleanup {
            let _ = std::fs::remove_file(p);
        }
    });
    let counts = counts.into_inner().unwrap();
    let failures = failures.into_inner().unwrap();
    println!(
        "fuzz: {} cases ({fixed} regression cases, {count} leaf-value, {text_count} text and {edge_count} edge cases generated with seed {seed}) in {:.1} s",
        jobs.len(),
        started.elapsed().as_secs_f64()
    );
    for (k, v) in &counts {
        println!("fuzz:   {k}: {v}");
    }
    let mut slowest = slowest.into_inner().unwrap();
    slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (secs, cmd) in slowest.iter().take(3) {
        println!("fuzz:   slowest: {secs:.2} s  {cmd}");
    }
    for (cmd, why) in &failures {
        println!("FAILED: {cmd}\n        {why}");
    }
    assert!(
        failures.is_empty(),
        "{} of {} fuzz cases failed (listed above)",
        failures.len(),
        jobs.len()
    );
}
