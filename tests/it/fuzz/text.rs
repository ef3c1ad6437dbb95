//! Text-level mutations of every kind of file rendersim reads: model files,
//! device profiles, experiment files, measurement CSVs, LOD instances,
//! meshes (`.obj`, `.idx`), PresentMon captures and shard files read back
//! by `--merge`.
//!
//! Where the leaf-value cases (the parent module) change one value and keep
//! the file well formed, these damage the text itself: lines dropped,
//! doubled (duplicate keys) or swapped, the file cut short, bytes and
//! control characters (NUL included) put in, numbers replaced by NaN,
//! infinities, overflows and negatives, a byte-order mark, CRLF line ends,
//! 20,000-deep nesting and a 5 MB string. Every case must still end in a
//! result or a clean error that names the damaged file.
//!
//! The shipped files are copied once into a tree inside the fuzz test's temp
//! folder (relative references between them keep working there), and each
//! mutated file is written into that tree under a name of its own.

use std::path::{Path, PathBuf};
use std::process::Command;

use rand::{Rng, seq::IndexedRandom};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::{Case, ROOT};

/// Bounds that keep one run small, per shipped model (a mutation of the text
/// cannot undo a `--set`, which applies after the file).
fn model_bounds(name: &str) -> Option<Vec<&'static str>> {
    if let Some((_, b)) = super::bases().into_iter().find(|(f, _)| *f == format!("models/{name}")) {
        return Some(b);
    }
    const MEM: &str = "run.max_memory=\"1GiB\"";
    const EVENTS: &str = "run.max_events=3000000";
    Some(match name {
        "h2-pass.toml" | "terrain.toml" | "terrain-geforce3.toml" | "city-geforce3.toml" => {
            vec!["run.frames=2", "run.warmup_frames=0", MEM, EVENTS]
        }
        "walkthrough-city.toml" | "walkthrough-forest.toml" => vec!["run.frames=20", MEM],
        "mfr-multigpu.toml" => vec!["run.events=40", MEM, EVENTS],
        _ => return None,
    })
}

/// The files of one kind that mutations start from, and how a mutated copy
/// is used.
#[derive(Debug, Clone)]
enum Kind {
    /// `rendersim run FILE --set BOUNDS... --json`.
    Model { bounds: Vec<&'static str> },
    /// `rendersim predict grid:16x16 --device FILE --json`.
    Device,
    /// `rendersim experiment FILE --slurm --out DIR`: the whole file is
    /// loaded, checked and expanded, nothing simulated.
    Experiment,
    /// `rendersim calibrate FILE --out P.toml --loo --holdout --json`.
    Csv,
    /// `rendersim lod-select FILE --json`.
    Instance,
    /// `rendersim vcache FILE --policy lru:16 --json`.
    Mesh,
    /// `rendersim experiment E --merge --out DIR` with one shard file of a
    /// finished split of E mutated.
    Shard,
    /// `rendersim replay FILE --json`: a PresentMon capture.
    Capture,
}

/// One starting file: where it lives in the tree, its text, and its kind.
#[derive(Debug, Clone)]
struct Seed {
    /// Folder in the tree the mutated copy is written into.
    folder: PathBuf,
    /// File extension of the copy (`toml`, `csv`, ...).
    ext: String,
    text: String,
    kind: Kind,
}

/// The copied tree and the seeds.
pub struct Tree {
    pub(super) root: PathBuf,
    seeds: Vec<Seed>,
    /// The sharded fixture experiment in the tree, and its finished split.
    pub(super) shard_experiment: PathBuf,
    pub(super) shard_out: PathBuf,
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_tree(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).unwrap();
        }
    }
}

pub(super) const INSTANCE: &str = "budget = \"10ms\"\n\n[[objects]]\nname = \"near\"\nlevels = [{ cost = \"1ms\", benefit = 1.0 }, \
{ cost = \"3ms\", benefit = 2.5 }]\n\n[[objects]]\nname = \"far\"\nlevels = [{ cost = \"2ms\", benefit = 0.5 }, \
{ cost = \"6ms\", benefit = 4.0 }]\n\n[[objects]]\nname = \"sky\"\nlevels = [{ cost = \"0.5ms\", benefit = 0.1 }]\n";

const OBJ: &str = "# a unit cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

/// Copies the shipped files into `dir` and finishes a three-way split of the
/// sharded fixture experiment there (with `bin`).
pub fn prepare(dir: &Path, bin: &Path) -> Tree {
    let root = dir.join("tree");
    let src = Path::new(ROOT);
    copy_tree(&src.join("models"), &root.join("models"));
    copy_tree(&src.join("experiments"), &root.join("experiments"));
    copy_tree(&src.join("docs/measurements"), &root.join("measurements"));
    copy_tree(&src.join("tests/fixtures/sharded"), &root.join("sharded"));
    std::fs::create_dir_all(root.join("instances")).unwrap();
    std::fs::create_dir_all(root.join("meshes")).unwrap();
    let mut seeds = Vec::new();
    let mut add = |folder: &Path, ext: &str, text: String, kind: Kind| {
        seeds.push(Seed {
            folder: folder.to_path_buf(),
            ext: ext.into(),
            text,
            kind,
        })
    };
    let files = |d: &Path, ext: &str| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == ext))
            .collect();
        v.sort();
        v
    };
    for p in files(&root.join("models"), "toml") {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if let Some(bounds) = model_bounds(&name) {
            add(
                &root.join("models"),
                "toml",
                std::fs::read_to_string(&p).unwrap(),
                Kind::Model { bounds },
            );
        }
    }
    for p in files(&root.join("models/devices"), "toml") {
        add(
            &root.join("models/devices"),
            "toml",
            std::fs::read_to_string(&p).unwrap(),
            Kind::Device,
        );
    }
    for d in [root.join("experiments"), root.join("experiments/state-sorting")] {
        for p in files(&d, "toml") {
            add(&d, "toml", std::fs::read_to_string(&p).unwrap(), Kind::Experiment);
        }
    }
    for d in [root.join("measurements"), root.join("measurements/nvidia-h200")] {
        for p in files(&d, "csv") {
            let text = std::fs::read_to_string(&p).unwrap();
            if text.starts_with("mesh,size,vs_loops") {
                add(&d, "csv", text, Kind::Csv);
            }
        }
    }
    add(&root.join("instances"), "toml", INSTANCE.into(), Kind::Instance);
    copy_tree(&src.join("tests/fixtures/presentmon"), &root.join("captures"));
    for p in files(&root.join("captures"), "csv") {
        let text = std::fs::read_to_string(&p).unwrap();
        add(&root.join("captures"), "csv", text, Kind::Capture);
    }
    add(&root.join("meshes"), "obj", OBJ.into(), Kind::Mesh);
    let idx: Vec<String> = (0..30u32)
        .flat_map(|i| [0, i + 1, i + 2])
        .map(|i| i.to_string())
        .collect();
    add(&root.join("meshes"), "idx", idx.join(" ") + "\n", Kind::Mesh);

    let shard_experiment = root.join("sharded/e.toml");
    let shard_out = root.join("sharded/out");
    for k in 1..=3 {
        let o = Command::new(bin)
            .args(["experiment", shard_experiment.to_str().unwrap(), "--quiet", "--out"])
            .arg(&shard_out)
            .args(["--shard", &format!("{k}/3")])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for k in 1..=3 {
        let p = shard_out.join(format!("shards/shard-{k}-of-3.json"));
        add(&shard_out, "json", std::fs::read_to_string(p).unwrap(), Kind::Shard);
    }
    Tree {
        root,
        seeds,
        shard_experiment,
        shard_out,
    }
}

/// Numbers that break things, put in place of a number of the text.
const NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e400",
    "-1e400",
    "-1",
    "0",
    "-0.0",
    "1e-320",
    "18446744073709551616",
    "4294967296",
    "9e18",
    "1e308",
    "0x10",
    "1_000",
    "+5",
    ".5",
    "5.",
    "1e",
    "--1",
];

/// Characters put into the text at random.
const CHARS: &[char] = &[
    '\0', '\u{1}', '\u{7f}', '\u{feff}', '\u{fffd}', '\t', '\r', '\n', '"', '\'', '\\', '[', ']', '{', '}', '=', ',',
    '#', ':', '.', ' ', 'é', '\u{202e}',
];

/// Byte offsets of the numbers in `text` (digit runs with sign, point, exponent).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')) {
            let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
            let mut j = i;
            while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.' || b[j] == b'e' || b[j] == b'-') {
                j += 1;
            }
            out.push((start, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// The nearest char boundary at or below `i`.
fn floor(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// One mutation of `text`, and what it was.
fn mutate_once(rng: &mut Xoshiro256PlusPlus, text: &str) -> (String, String) {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let pick_line = |rng: &mut Xoshiro256PlusPlus| rng.random_range(0..lines.len().max(1));
    match rng.random_range(0..14) {
        0 if !lines.is_empty() => {
            let i = pick_line(rng);
            let mut l = lines.clone();
            let gone = l.remove(i);
            (l.concat(), format!("line {} dropped ({:?})", i + 1, gone.trim_end()))
        }
        1 if !lines.is_empty() => {
            let i = pick_line(rng);
            let mut l = lines.clone();
            l.insert(i, lines[i]);
            (
                l.concat(),
                format!("line {} doubled ({:?})", i + 1, lines[i].trim_end()),
            )
        }
        2 if lines.len() > 1 => {
            let (i, j) = (pick_line(rng), pick_line(rng));
            let mut l = lines.clone();
            l.swap(i, j);
            (l.concat(), format!("lines {} and {} swapped", i + 1, j + 1))
        }
        3 => {
            let at = floor(text, rng.random_range(0..=text.len()));
            (text[..at].to_string(), format!("cut at byte {at}"))
        }
        4..=5 => {
            let at = floor(text, rng.random_range(0..=text.len()));
            let c = *CHARS.choose(rng).unwrap();
            (
                format!("{}{c}{}", &text[..at], &text[at..]),
                format!("{c:?} put in at byte {at}"),
            )
        }
        6..=8 => {
            let spots = numbers(text);
            let Some(&(a, b)) = spots.choose(rng) else {
                return mutate_once(rng, text);
            };
            let n = *NUMBERS.choose(rng).unwrap();
            (
                format!("{}{n}{}", &text[..a], &text[b..]),
                format!("number {:?} at byte {a} replaced by {n}", &text[a..b]),
            )
        }
        9 => (format!("\u{feff}{text}"), "a byte-order mark in front".into()),
        10 => (text.replace('\n', "\r\n"), "CRLF line ends".into()),
        11 => {
            let depth = 20_000;
            let at = floor(text, rng.random_range(0..=text.len()));
            let deep = if rng.random_bool(0.5) {
                format!("\nfuzz_deep = {}{}\n", "[".repeat(depth), "]".repeat(depth))
            } else {
                format!("\nfuzz_deep = {}1{}\n", "{ a = ".repeat(depth), " }".repeat(depth))
            };
            (
                format!("{}{deep}{}", &text[..at], &text[at..]),
                format!("{depth}-deep nesting at byte {at}"),
            )
        }
        12 => {
            let at = floor(text, rng.random_range(0..=text.len()));
            let big = "A".repeat(5 << 20);
            (
                format!("{}\"{big}\"{}", &text[..at], &text[at..]),
                format!("a 5 MB string at byte {at}"),
            )
        }
        _ => (String::new(), "emptied".into()),
    }
}

/// One to three mutations of `text`.
fn mutate(rng: &mut Xoshiro256PlusPlus, text: &str) -> (String, String) {
    let mut t = text.to_string();
    let mut what = Vec::new();
    for _ in 0..rng.random_range(1..=3) {
        let (next, w) = mutate_once(rng, &t);
        t = next;
        what.push(w);
        if t.len() > (4 << 20) {
            // One huge insertion is enough (and keeps the case's input printable).
            break;
        }
    }
    (t, what.join("; "))
}

/// A text-mutation case: a mutated copy of a shipped file, and the command
/// that reads it.
pub fn case(rng: &mut Xoshiro256PlusPlus, n: usize, tree: &Tree) -> Case {
    // A kind first, then one of its files: each kind gets its share, however
    // many files of it are shipped.
    let kinds: Vec<std::mem::Discriminant<Kind>> = {
        let mut k: Vec<_> = tree.seeds.iter().map(|s| std::mem::discriminant(&s.kind)).collect();
        k.dedup();
        k
    };
    let kind = *kinds.choose(rng).unwrap();
    let of_kind: Vec<&Seed> = tree
        .seeds
        .iter()
        .filter(|s| std::mem::discriminant(&s.kind) == kind)
        .collect();
    let seed = (*of_kind.choose(rng).unwrap()).clone();
    let (text, what) = mutate(rng, &seed.text);
    let name = format!("fuzz-{n}.{}", seed.ext);
    let path = seed.folder.join(&name);
    let p = path.display().to_string();
    let mut blame = vec![name.clone()];
    let mut allow_null: Vec<&'static str> = Vec::new();
    let mut json = true;
    let mut files = vec![(p.clone(), text)];
    let args: Vec<String> = match &seed.kind {
        Kind::Model { bounds } => {
            let mut a = vec!["run".to_string(), p.clone()];
            for b in bounds {
                a.push("--set".into());
                a.push(b.to_string());
                blame.push(b.split_once('=').unwrap().0.to_string());
            }
            blame.extend(["max_events".into(), "max_memory".into()]);
            // A walkthrough scene without view cells has no view-cell size.
            allow_null.push("view_cell_m");
            a.push("--json".into());
            a
        }
        Kind::Device => {
            allow_null.push("measured");
            vec![
                "predict".into(),
                "grid:16x16".into(),
                "--device".into(),
                p.clone(),
                "--json".into(),
            ]
        }
        Kind::Experiment => {
            json = false;
            vec![
                "experiment".into(),
                p.clone(),
                "--slurm".into(),
                "--out".into(),
                "out".into(),
            ]
        }
        Kind::Csv => {
            allow_null.push("linear_baseline_loo");
            vec![
                "calibrate".into(),
                p.clone(),
                "--out".into(),
                "profile.toml".into(),
                "--loo".into(),
                "--holdout".into(),
                "--json".into(),
            ]
        }
        Kind::Instance => {
            // An object left out of the selection has no level.
            allow_null.push("selection");
            vec!["lod-select".into(), p.clone(), "--json".into()]
        }
        Kind::Capture => {
            // A capture without tearing has no tear rate.
            allow_null.push("torn_per_second");
            vec!["replay".into(), p.clone(), "--json".into()]
        }
        Kind::Mesh => vec![
            "vcache".into(),
            p.clone(),
            "--policy".into(),
            "lru:16".into(),
            "--json".into(),
        ],
        Kind::Shard => {
            // The mutated file replaces one shard of a copy of the split.
            let file = seed
                .text
                .split("\"shard\":")
                .nth(1)
                .and_then(|s| s.split(',').next())
                .unwrap_or("1");
            let shard_name = format!("shard-{file}-of-3.json");
            let (_, text) = files.pop().unwrap();
            files.push((format!("out/shards/{shard_name}"), text));
            blame = vec![shard_name, "shards".into()];
            json = false;
            vec![
                "experiment".into(),
                tree.shard_experiment.display().to_string(),
                "--quiet".into(),
                "--merge".into(),
                "--out".into(),
                "out".into(),
            ]
        }
    };
    let copy = match seed.kind {
        Kind::Shard => vec![(tree.shard_out.clone(), "out".to_string())],
        _ => vec![],
    };
    let rel = path.strip_prefix(&tree.root).unwrap_or(&path).display().to_string();
    Case {
        what: format!("text: {rel}: {}", what.chars().take(300).collect::<String>()),
        args,
        files,
        blame,
        json,
        allow_null,
        copy,
        cleanup: if matches!(seed.kind, Kind::Shard) {
            vec![]
        } else {
            vec![path]
        },
        must_refuse: false,
        ..Case::default()
    }
}
