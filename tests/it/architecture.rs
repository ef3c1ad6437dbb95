//! docs/ARCHITECTURE.md stays true to the code: every file under `src/` is
//! named in it (a `mod.rs` by its folder, `name/`), so a newcomer reading the
//! map finds every file, and a file added without a word there fails here.

use std::path::Path;

fn files(dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(
                p.strip_prefix(env!("CARGO_MANIFEST_DIR"))
                    .unwrap()
                    .display()
                    .to_string(),
            );
        }
    }
}

#[test]
fn every_source_file_is_on_the_architecture_map() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).unwrap();
    let mut all = Vec::new();
    files(&root.join("src"), &mut all);
    all.sort();
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
        "docs/ARCHITECTURE.md does not name these files under src/ (add a line for each):\n{}",
        missing.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n")
    );
}
