//! docs/ARCHITECTURE.md stays true to the code: every file under `src/` is
//! named in it (a `mod.rs` by its folder, `name/`), so a newcomer reading the
//! map finds every file, and a file added without a word there fails here;
//! and no function in `src/` runs over 150 lines (issue 27).

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
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all = Vec::new();
    files(&root.join("src"), &mut all);
    let long: Vec<String> = all
        .iter()
        .filter(|f| f.ends_with(".rs"))
        .flat_map(|f| {
            let text = std::fs::read_to_string(root.join(f)).unwrap();
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
