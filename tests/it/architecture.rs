//! The layers hold, and docs/ARCHITECTURE.md stays true to the code:
//!
//! - the crates' dependency graph (`cargo metadata`) has no edge that the
//!   map's "Layers" table does not allow, and only `rendersim-measure`
//!   depends on wgpu;
//! - inside `rendersim-models`, a module's code names only the modules
//!   listed before it;
//! - every source file of every crate is named on the map (a `mod.rs` by its
//!   folder, `name/`);
//! - no function runs over 150 lines (issue 27);
//! - the frame pipeline's files import in no circle but those listed to
//!   take apart (issue 55);
//! - the frame pipeline's units read their specs, never the raw model: their
//!   files' code does not name `FramePipelineConfig` (issue 55).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn files(dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p.strip_prefix(root()).unwrap().display().to_string());
        }
    }
}

/// Every source folder of the workspace: `src/` and each crate's `src/`.
fn source_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![root().join("src")];
    let mut crates: Vec<PathBuf> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    crates.sort();
    dirs.extend(crates);
    dirs
}

fn all_source_files() -> Vec<String> {
    let mut all = Vec::new();
    for d in source_dirs() {
        files(&d, &mut all);
    }
    all.sort();
    all
}

/// The "Layers" table of docs/ARCHITECTURE.md, in its order: each crate
/// and the crates it may depend on.
fn documented_layers(doc: &str) -> Vec<(String, BTreeSet<String>)> {
    let section = doc
        .split("\n## Layers\n")
        .nth(1)
        .expect("docs/ARCHITECTURE.md has a \"## Layers\" section");
    let section = section.split("\n## ").next().unwrap();
    let mut layers = Vec::new();
    for line in section.lines().filter(|l| l.starts_with("| rendersim")) {
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        assert_eq!(cells.len(), 3, "a Layers row has crate, folder, may depend on: {line}");
        let allowed = cells[2]
            .split(',')
            .map(str::trim)
            .filter(|c| c.starts_with("rendersim"))
            .map(String::from)
            .collect();
        layers.push((cells[0].to_string(), allowed));
    }
    layers
}

/// Each workspace crate's dependencies (normal, build and dev) as
/// `cargo metadata` reports them.
fn actual_dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(root())
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    meta["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d["name"].as_str().unwrap().to_string())
                .collect();
            (p["name"].as_str().unwrap().to_string(), deps)
        })
        .collect()
}

/// The edges of `actual` between workspace crates that `allowed` does not
/// list, and the crates that are not in the table at all.
fn layer_violations(
    actual: &BTreeMap<String, BTreeSet<String>>,
    allowed: &BTreeMap<String, BTreeSet<String>>,
) -> Vec<String> {
    let mut bad = Vec::new();
    for (krate, deps) in actual {
        let Some(ok) = allowed.get(krate) else {
            bad.push(format!("{krate} is not in the Layers table"));
            continue;
        };
        for d in deps.iter().filter(|d| actual.contains_key(*d)) {
            if !ok.contains(d) {
                bad.push(format!("{krate} -> {d}"));
            }
        }
    }
    bad
}

#[test]
fn the_layer_table_itself_only_points_down() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let layers = documented_layers(&doc);
    // In the table's order, a crate may name only crates in the rows above it.
    let order: Vec<&String> = layers.iter().map(|(k, _)| k).collect();
    assert_eq!(order.len(), 5, "five crates in the Layers table: {order:?}");
    assert_eq!(order[0], "rendersim-engine");
    assert!(layers[0].1.is_empty(), "the engine depends on no other crate");
    for (i, (krate, allowed)) in layers.iter().enumerate() {
        for d in allowed {
            let j = order
                .iter()
                .position(|o| *o == d)
                .unwrap_or_else(|| panic!("{krate} may depend on unknown {d}"));
            assert!(j < i, "the table lets {krate} depend on {d}, which is not below it");
        }
    }
}

#[test]
fn the_crates_depend_only_on_the_layers_below_them() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let allowed = documented_layers(&doc).into_iter().collect();
    let actual = actual_dependencies();
    let bad = layer_violations(&actual, &allowed);
    assert!(
        bad.is_empty(),
        "dependencies that docs/ARCHITECTURE.md's Layers table does not allow:\n{}",
        bad.join("\n")
    );
    let on_wgpu: Vec<&String> = actual
        .iter()
        .filter(|(_, d)| d.contains("wgpu"))
        .map(|(k, _)| k)
        .collect();
    assert_eq!(
        on_wgpu,
        ["rendersim-measure"],
        "only the measurement crate depends on wgpu"
    );
}

#[test]
fn an_extra_edge_is_a_violation() {
    // The check itself can fail: the engine reaching up to the models, and
    // a crate missing from the table, are both reported.
    let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
    let allowed = BTreeMap::from([
        ("rendersim-engine".to_string(), set(&[])),
        ("rendersim-models".to_string(), set(&["rendersim-engine"])),
    ]);
    let mut actual = BTreeMap::from([
        ("rendersim-engine".to_string(), set(&["rand", "rendersim-models"])),
        ("rendersim-models".to_string(), set(&["rendersim-engine", "serde"])),
    ]);
    assert_eq!(
        layer_violations(&actual, &allowed),
        ["rendersim-engine -> rendersim-models"]
    );
    actual.insert("rendersim-extra".to_string(), set(&[]));
    assert_eq!(layer_violations(&actual, &allowed).len(), 2);
}

/// The modules of `rendersim-models` in their documented order.
fn model_module_order(doc: &str) -> Vec<String> {
    let line = doc
        .lines()
        .find(|l| l.starts_with("Modules of `rendersim-models`, in order:"))
        .expect("docs/ARCHITECTURE.md lists the models' module order");
    line.split(':')
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches('.')
        .split(',')
        .map(|m| m.trim().to_string())
        .collect()
}

/// The `crate::MODULE` names a file's code uses (comments and strings left out).
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut strip = Strip::default();
    let mut names = BTreeSet::new();
    for line in text.lines() {
        let code = strip.code(line);
        for (i, _) in code.match_indices("crate::") {
            if i > 0 && code[..i].ends_with('$') {
                continue;
            }
            let rest = &code[i + "crate::".len()..];
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                names.insert(name);
            }
        }
        // `use crate::{a::.., b::..}`: the names after the brace.
        for (i, _) in code.match_indices("crate::{") {
            let rest = &code[i + "crate::{".len()..];
            for part in rest.split(['}', ';']).next().unwrap().split(',') {
                let name: String = part
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    names.insert(name);
                }
            }
        }
    }
    names
}

#[test]
fn each_model_module_names_only_the_modules_before_it() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let order = model_module_order(&doc);
    assert_eq!(order, ["limits", "config", "components", "scene", "systems"]);
    let src = root().join("crates/models/src");
    let mut bad = Vec::new();
    for (i, module) in order.iter().enumerate() {
        let mut files_of = Vec::new();
        let (dir, file) = (src.join(module), src.join(format!("{module}.rs")));
        if dir.is_dir() {
            files(&dir, &mut files_of);
        }
        if file.is_file() {
            files_of.push(file.strip_prefix(root()).unwrap().display().to_string());
        }
        assert!(!files_of.is_empty(), "no source for models module {module}");
        let later: BTreeSet<&String> = order[i + 1..].iter().collect();
        for f in files_of.iter().filter(|f| f.ends_with(".rs")) {
            let text = std::fs::read_to_string(root().join(f)).unwrap();
            for name in crate_paths(&text) {
                if later.contains(&name) {
                    bad.push(format!("{f} names crate::{name}, a module after {module}"));
                }
            }
        }
    }
    assert!(bad.is_empty(), "models modules reaching up:\n{}", bad.join("\n"));
}

#[test]
fn crate_paths_are_read_from_code_only() {
    let text = "use crate::config::Rate; // crate::systems\nuse crate::{engine::Time, output::x};\nlet s = \"crate::scene\";\n/// [`crate::plot`]\n";
    let names: Vec<String> = crate_paths(text).into_iter().collect();
    assert_eq!(names, ["config", "engine", "output"]);
}

#[test]
fn every_source_file_is_on_the_architecture_map() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let all = all_source_files();
    let missing: Vec<&String> = all
        .iter()
        .filter(|f| {
            let p = Path::new(f.as_str());
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let named = if name == "mod.rs" {
                let folder = p.parent().unwrap().file_name().unwrap().to_string_lossy().to_string();
                format!("{folder}/")
            } else {
                name
            };
            // The file's name as a word of the map (not inside a longer name).
            !doc.match_indices(&named).any(|(i, _)| {
                let before = doc[..i].chars().next_back();
                !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '-')
            })
        })
        .collect();
    assert!(
        missing.is_empty(),
        "docs/ARCHITECTURE.md does not name these source files (add a line for each):\n{}",
        missing.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n")
    );
}

/// Code of one line without string, char and comment contents; `state`
/// carries an open block comment, string or raw string across lines.
#[derive(Default)]
struct Strip {
    block: bool,
    string: bool,
    raw: Option<String>,
}

impl Strip {
    fn code(&mut self, line: &str) -> String {
        let b: Vec<char> = line.chars().collect();
        let (mut out, mut i) = (String::new(), 0);
        let at = |i: usize, s: &str| b[i..].iter().take(s.len()).collect::<String>() == s;
        while i < b.len() {
            if self.block {
                if at(i, "*/") {
                    self.block = false;
                    i += 2;
                } else {
                    i += 1;
                }
                continue;
            }
            if let Some(end) = &self.raw {
                if at(i, end) {
                    i += end.len();
                    self.raw = None;
                } else {
                    i += 1;
                }
                continue;
            }
            if self.string {
                match b[i] {
                    '\\' => i += 2,
                    '"' => {
                        self.string = false;
                        i += 1
                    }
                    _ => i += 1,
                }
                continue;
            }
            let word_start = i == 0 || !(b[i - 1].is_alphanumeric() || b[i - 1] == '_');
            if at(i, "//") {
                break;
            } else if at(i, "/*") {
                self.block = true;
                i += 2;
            } else if b[i] == 'r' && word_start && b.get(i + 1).is_some_and(|&c| c == '"' || c == '#') {
                let hashes = b[i + 1..].iter().take_while(|&&c| c == '#').count();
                if b.get(i + 1 + hashes) == Some(&'"') {
                    self.raw = Some(format!("\"{}", "#".repeat(hashes)));
                    i += 2 + hashes;
                } else {
                    out.push(b[i]);
                    i += 1;
                }
            } else if b[i] == '"' {
                self.string = true;
                i += 1;
            } else if b[i] == '\'' && (b.get(i + 2) == Some(&'\'') || (b.get(i + 1) == Some(&'\\'))) {
                // A char literal ('x', '\n', '\u{..}'); a lifetime has no closing quote.
                let close = b[i + 1..].iter().skip(1).position(|&c| c == '\'').map_or(1, |p| p + 2);
                i += close + 1;
            } else {
                out.push(b[i]);
                i += 1;
            }
        }
        out
    }
}

/// Every function's (name, first line, lines) in Rust source `text`: from
/// its `fn` line to the line of the brace that closes its body.
fn function_lengths(text: &str) -> Vec<(String, usize, usize)> {
    let mut strip = Strip::default();
    let (mut out, mut open) = (Vec::new(), Vec::<(String, usize, i64)>::new());
    let (mut depth, mut brackets) = (0i64, 0i64);
    let mut pending: Option<(String, usize)> = None;
    for (no, line) in text.lines().enumerate().map(|(i, l)| (i + 1, l)) {
        let code = strip.code(line);
        // Where a `fn` keyword starts on this line, and the name after it.
        let is_word = |c: char| c.is_alphanumeric() || c == '_';
        let chars: Vec<char> = code.chars().collect();
        // `fn NAME(` or `fn NAME<`: an item, not a `fn(..)` pointer type.
        let item_name = |i: usize| -> Option<String> {
            let rest: String = chars[i + 2..].iter().collect();
            let after = rest.strip_prefix(char::is_whitespace)?.trim_start();
            let name: String = after.chars().take_while(|&c| is_word(c)).collect();
            let next = after[name.len()..].trim_start().chars().next();
            (!name.is_empty() && matches!(next, Some('(' | '<'))).then_some(name)
        };
        let found = (0..chars.len().saturating_sub(2))
            .filter(|&i| chars[i] == 'f' && chars[i + 1] == 'n' && (i == 0 || !is_word(chars[i - 1])))
            .find_map(|i| item_name(i).map(|n| (i, n)));
        let (fn_at, name) = match found {
            Some((i, n)) => (Some(i), n),
            None => (None, String::new()),
        };
        for (i, &ch) in chars.iter().enumerate() {
            if Some(i) == fn_at {
                pending = Some((name.clone(), no));
                brackets = 0;
            }
            match ch {
                '(' | '[' => brackets += 1,
                ')' | ']' => brackets -= 1,
                '{' => {
                    depth += 1;
                    if let Some((name, start)) = pending.take() {
                        open.push((name, start, depth));
                    }
                }
                '}' => {
                    if open.last().is_some_and(|o| o.2 == depth) {
                        let (name, start, _) = open.pop().unwrap();
                        out.push((name, start, no - start + 1));
                    }
                    depth -= 1;
                }
                // A declaration without a body (a `;` not inside a type's brackets).
                ';' if brackets <= 0 => pending = None,
                _ => {}
            }
        }
    }
    out
}

/// Most lines a function in `src/` may have (issue 27: functions a reader
/// can hold; `scripts/long-functions.py` lists them too).
const MAX_FUNCTION_LINES: usize = 150;

#[test]
fn function_lengths_are_counted_through_strings_comments_and_array_types() {
    let text = "fn a(x: [u8; 4]) -> u8 {\n    let s = \"}{\"; // }\n    let c = '}';\n    /* } */ x[0]\n}\n\
                struct S { f: fn(u8) -> u8 }\ntrait T { fn d(&self); }\nfn b<'a>(s: &'a str) -> &'a str {\n    r#\"}\"#;\n    s\n}\n";
    assert_eq!(
        function_lengths(text),
        vec![("a".to_string(), 1, 5), ("b".to_string(), 8, 4)]
    );
}

#[test]
fn no_function_in_src_is_longer_than_a_reader_can_hold() {
    let long: Vec<String> = all_source_files()
        .iter()
        .filter(|f| f.ends_with(".rs"))
        .flat_map(|f| {
            let text = std::fs::read_to_string(root().join(f)).unwrap();
            function_lengths(&text)
                .into_iter()
                .filter(|(_, _, n)| *n > MAX_FUNCTION_LINES)
                .map(move |(name, start, n)| format!("{f}:{start} {name}: {n} lines"))
        })
        .collect();
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines; split them by what they do:\n{}",
        long.join("\n")
    );
}

/// The frame pipeline's files (a folder, `cpu_thread/`, is one) and the
/// sibling files each one's code names: `super::NAME` from a file of the
/// folder (`super::super::NAME` inside an inline `mod` or from a file of a
/// subfolder), `crate::systems::frame_pipeline::NAME` from anywhere in it.
fn pipeline_imports(dir: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut nodes: BTreeMap<String, Vec<(PathBuf, usize)>> = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() {
            for f in std::fs::read_dir(&p).unwrap() {
                let f = f.unwrap().path();
                if f.extension().is_some_and(|x| x == "rs") {
                    // A folder's mod.rs sits where a file of the folder above
                    // would; its other files one level down.
                    let depth = usize::from(f.file_stem().unwrap() != "mod");
                    nodes.entry(name.clone()).or_default().push((f, depth));
                }
            }
        } else if p.extension().is_some_and(|x| x == "rs") && name != "mod" {
            nodes.entry(name).or_default().push((p, 0));
        }
    }
    let known: BTreeSet<String> = nodes.keys().cloned().collect();
    let mut graph = BTreeMap::new();
    for (node, files_of) in &nodes {
        let mut names = BTreeSet::new();
        for (f, depth) in files_of {
            let text = std::fs::read_to_string(f).unwrap();
            names.extend(sibling_paths(&text, *depth));
        }
        names.retain(|n| n != node && known.contains(n));
        graph.insert(node.clone(), names);
    }
    graph
}

/// The names of a module's siblings that `text`'s code reaches (see
/// [`pipeline_imports`]), for a file `depth` levels below the folder.
fn sibling_paths(text: &str, depth: usize) -> BTreeSet<String> {
    let ident = |s: &str| -> String { s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    let mut strip = Strip::default();
    let mut names = BTreeSet::new();
    // Brace depths at which inline modules (`mod tests {`) opened.
    let mut mods: Vec<i64> = Vec::new();
    let mut braces: i64 = 0;
    for line in text.lines() {
        let code = strip.code(line);
        let t = code.trim_start();
        let t = t.strip_prefix("pub ").unwrap_or(t);
        if t.starts_with("mod ") && t.trim_end().ends_with('{') {
            mods.push(braces);
        }
        let mut rest = code.as_str();
        while let Some(i) = rest.find("super::") {
            let mut s = &rest[i..];
            let mut hops = 0;
            while let Some(r) = s.strip_prefix("super::") {
                hops += 1;
                s = r;
            }
            if hops == mods.len() + depth + 1 {
                if let Some(group) = s.strip_prefix('{') {
                    for part in group.split(['}', ';']).next().unwrap().split(',') {
                        names.insert(ident(part.trim()));
                    }
                } else {
                    names.insert(ident(s));
                }
            }
            rest = s;
        }
        for (i, _) in code.match_indices("crate::systems::frame_pipeline::") {
            names.insert(ident(&code[i + "crate::systems::frame_pipeline::".len()..]));
        }
        braces += code.matches('{').count() as i64 - code.matches('}').count() as i64;
        while mods.last().is_some_and(|&d| braces <= d) {
            mods.pop();
        }
    }
    names.remove("");
    names
}

/// The circles of a graph: its strongly connected parts of two or more
/// nodes, each sorted (Tarjan's algorithm).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let i = t.index.len();
        t.index.insert(v, i);
        t.low.insert(v, i);
        t.stack.push(v);
        t.on.insert(v);
        for w in t.g.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.on.contains(w) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut part = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                part.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if part.len() > 1 {
                part.sort();
                t.out.push(part);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out.sort();
    t.out
}

/// The frame pipeline's import circles still there, each to be taken apart
/// (issue 55). None: the last, the geometry and fragment stages calling each
/// other, went when the held triangle became a slot of the triangle link.
const KNOWN_PIPELINE_CIRCLES: &[&[&str]] = &[];

#[test]
fn no_import_circle_among_the_frame_pipelines_files_but_those_listed_to_take_apart() {
    let graph = pipeline_imports(&root().join("crates/models/src/systems/frame_pipeline"));
    assert!(
        graph["model"].contains("display") && graph["summary"].contains("analytic"),
        "{graph:?}"
    );
    let found = circles(&graph);
    let known: Vec<Vec<String>> = KNOWN_PIPELINE_CIRCLES
        .iter()
        .map(|c| c.iter().map(|s| s.to_string()).collect())
        .collect();
    assert_eq!(
        found, known,
        "the frame pipeline's import circles changed: a new one must be taken apart (a file named by two \
         others moves below both), and one taken apart leaves KNOWN_PIPELINE_CIRCLES"
    );
}

/// The frame pipeline's units and the links between them: each holds
/// its spec (`unit_specs.rs`, the display's `DisplaySpec`).
const PIPELINE_UNIT_FILES: &[&str] = &[
    "cpu_thread/mod.rs",
    "cpu_thread/pacing.rs",
    "cpu_thread/fixed_work.rs",
    "front_end.rs",
    "geometry_stage.rs",
    "fragment_stage.rs",
    "display.rs",
    "links.rs",
    "bus_copy.rs",
    "quiet.rs",
];

/// The lines of `text`'s code (strings and comments left out) that name `name`.
fn code_lines_naming(text: &str, name: &str) -> Vec<usize> {
    let mut strip = Strip::default();
    text.lines()
        .enumerate()
        .filter(|(_, l)| strip.code(l).contains(name))
        .map(|(i, _)| i + 1)
        .collect()
}

#[test]
fn the_pipelines_units_never_name_the_raw_model() {
    let dir = root().join("crates/models/src/systems/frame_pipeline");
    let mut found = Vec::new();
    for f in PIPELINE_UNIT_FILES {
        let text = std::fs::read_to_string(dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        for line in code_lines_naming(&text, "FramePipelineConfig") {
            found.push(format!("{f}:{line}"));
        }
    }
    assert!(
        found.is_empty(),
        "a unit names the raw model (give it what it reads in its spec, unit_specs.rs): {found:?}"
    );
    // The check reads code, not the docs that name the type.
    let text = "/// Not `FramePipelineConfig`.\nfn f(c: &FramePipelineConfig) {}\n";
    assert_eq!(code_lines_naming(text, "FramePipelineConfig"), [2]);
}

#[test]
fn sibling_paths_and_circles_are_found_in_code_only() {
    let text = "use super::a::X;\nuse super::{b::Y, c};\n// use super::d;\nlet s = \"super::e\";\nmod tests {\n    use super::*;\n    use super::super::f::Z;\n}\nuse crate::systems::frame_pipeline::g::W;\n";
    let names: Vec<String> = sibling_paths(text, 0).into_iter().collect();
    assert_eq!(names, ["a", "b", "c", "f", "g"]);
    // From a file of a subfolder, `super::` is the subfolder.
    let names: Vec<String> = sibling_paths("use super::pacing::P;\nuse super::super::links::L;\n", 1)
        .into_iter()
        .collect();
    assert_eq!(names, ["links"]);
    let g: BTreeMap<String, BTreeSet<String>> =
        [("a", vec!["b"]), ("b", vec!["c"]), ("c", vec!["a"]), ("d", vec!["a"])]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
            .collect();
    assert_eq!(circles(&g), [vec!["a", "b", "c"]]);
}
