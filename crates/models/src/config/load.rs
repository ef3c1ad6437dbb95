//! Reading model files: TOML text -> table -> `--set` patches -> typed,
//! validated configuration. Every error names the file, the key path, the
//! line where the key stands (when it came from the file) and, for a
//! misspelt key, the closest valid one.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// Where a model came from and its text.
#[derive(Debug, Clone)]
pub struct ModelSource {
    /// A file path, or `<embedded default model>`.
    pub name: String,
    /// The TOML text.
    pub text: String,
    /// Directory relative paths inside the model resolve against.
    pub base_dir: PathBuf,
    /// Keys given on the command line, in the order applied: (dotted key,
    /// how it was given, e.g. `--set cpu.per_draw=17`). An error in such a
    /// key names the option instead of a line of the file.
    pub overrides: Vec<(String, String)>,
}

/// Errors of reading and validating model files.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read model file {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The text is not valid TOML.
    #[error("{file}: malformed TOML: {message}")]
    Syntax {
        /// File name.
        file: String,
        /// The parser's message (it names line and column).
        message: String,
    },
    /// A command-line option's value cannot go into a model.
    #[error("{option}: {reason}")]
    Override {
        /// The option as given, e.g. `--seed 18446744073709551615`.
        option: String,
        /// Why.
        reason: String,
    },
    /// A `--set key=value` could not be applied.
    #[error("--set {assignment:?}: {reason}")]
    Set {
        /// The assignment as given.
        assignment: String,
        /// Why.
        reason: String,
    },
    /// A key is unknown or its value is invalid.
    #[error("{file}{}: key `{key}`: {message}{}", line.map(|l| format!(":{l}")).unwrap_or_default(), suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default())]
    Invalid {
        /// File name; for a value given on the command line, that option
        /// and the file (``value from `--set cpu.per_draw=17` (applied to
        /// m.toml)``), without a line.
        file: String,
        /// Dotted key path.
        key: String,
        /// 1-based line in the file, when the key stands there.
        line: Option<usize>,
        /// What is wrong.
        message: String,
        /// The closest valid key, for a misspelt one.
        suggestion: Option<String>,
    },
}

impl ModelSource {
    /// Reads a model file.
    pub fn from_file(path: &Path) -> Result<ModelSource, ConfigError> {
        let text = crate::limits::read_input_string(path, crate::limits::InputKind::Text).map_err(|source| {
            ConfigError::Io {
                path: path.display().to_string(),
                source,
            }
        })?;
        Ok(ModelSource {
            name: path.display().to_string(),
            text,
            base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            overrides: Vec::new(),
        })
    }

    /// A model given as text (the embedded default, tests).
    pub fn from_text(name: &str, text: &str) -> ModelSource {
        ModelSource {
            name: name.to_string(),
            text: text.to_string(),
            base_dir: PathBuf::from("."),
            overrides: Vec::new(),
        }
    }

    /// Records that `key` was given on the command line as `origin`.
    pub fn note_override(&mut self, key: &str, origin: String) {
        self.overrides.push((key.to_string(), origin));
    }

    /// The command-line option that set `key` or a table above it (the last
    /// one applied), else one that set a key inside `key` (a distribution's
    /// `sigma` for an error about the distribution), if any.
    pub fn override_of(&self, key: &str) -> Option<&str> {
        let below = |a: &str, b: &str| a.strip_prefix(b).is_some_and(|rest| rest.starts_with('.'));
        let last = |f: &dyn Fn(&str) -> bool| self.overrides.iter().rev().find(|(k, _)| f(k)).map(|(_, o)| o.as_str());
        last(&|k| key == k || below(key, k)).or_else(|| last(&|k| below(k, key)))
    }

    /// Parses the text into a TOML table, with the hardware file that a
    /// top-level `hardware = "PATH"` names merged under it
    /// ([`super::hardware`]).
    pub fn table(&self) -> Result<toml::Table, ConfigError> {
        let mut t = self.own_table()?;
        super::hardware::merge_hardware(self, &mut t)?;
        Ok(t)
    }

    /// Parses the text alone into a TOML table.
    pub fn own_table(&self) -> Result<toml::Table, ConfigError> {
        self.text.parse::<toml::Table>().map_err(|e| ConfigError::Syntax {
            file: self.name.clone(),
            message: e.to_string().trim().to_string(),
        })
    }

    /// 1-based line of the dotted `key` in the text, if it stands there
    /// (a key given only with `--set` has none).
    pub fn line_of(&self, key: &str) -> Option<usize> {
        if self.text.trim().is_empty() {
            return None;
        }
        let doc = toml_edit::Document::parse(self.text.as_str()).ok()?;
        let parts: Vec<&str> = key.split('.').collect();
        find_item(doc.as_item(), &parts, None).map(|s| line_at(&self.text, s.start))
    }
}

type Span = Option<std::ops::Range<usize>>;

/// The entry of `parts` in a table: `a` then `b.c` for `a.b.c`, or a quoted
/// key holding dots (`"b.c"`, as experiment `[set]` tables write keys).
fn table_entry<T>(parts: &[&str], get: impl Fn(&str) -> Option<T>) -> Option<(T, usize)> {
    (1..=parts.len()).find_map(|n| get(&parts[..n].join(".")).map(|e| (e, n)))
}

fn find_item(item: &toml_edit::Item, parts: &[&str], span: Span) -> Span {
    if parts.is_empty() {
        return span;
    }
    let first = parts[0];
    let rest = &parts[1..];
    match item {
        toml_edit::Item::Table(t) => match table_entry(parts, |k| t.get_key_value(k)) {
            Some(((k, v), n)) => find_item(v, &parts[n..], k.span().or(v.span()).or(span)),
            None => None,
        },
        toml_edit::Item::ArrayOfTables(a) => match first.parse::<usize>().ok().and_then(|i| a.get(i)) {
            Some(t) => find_item(&toml_edit::Item::Table(t.clone()), rest, t.span().or(span)),
            None => span,
        },
        toml_edit::Item::Value(v) => find_value(v, parts, span),
        toml_edit::Item::None => span,
    }
}

fn find_value(v: &toml_edit::Value, parts: &[&str], span: Span) -> Span {
    if parts.is_empty() {
        return span;
    }
    let first = parts[0];
    let rest = &parts[1..];
    match v {
        toml_edit::Value::InlineTable(t) => match table_entry(parts, |k| t.get_key_value(k)) {
            Some(((k, v2), n)) => find_item(v2, &parts[n..], k.span().or(v2.span()).or(span)),
            None => None,
        },
        toml_edit::Value::Array(a) => match first.parse::<usize>().ok().and_then(|i| a.get(i)) {
            Some(v2) => find_value(v2, rest, v2.span().or(span)),
            None => None,
        },
        _ => None,
    }
}

fn line_at(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Deserializes `table` into `T`, turning serde's errors into
/// [`ConfigError::Invalid`] with key path, line and suggestion.
pub fn deserialize<T: DeserializeOwned>(table: &toml::Table, src: &ModelSource) -> Result<T, ConfigError> {
    // A table written as an array is refused, not read field by position.
    let de = super::strict::Strict(table.clone());
    serde_path_to_error::deserialize::<_, T>(de).map_err(|e| {
        let mut path = dotted_path(&e.path().to_string());
        let message = e.inner().to_string();
        // toml appends "in `key`" lines; the key path is reported separately.
        let mut message: String = message
            .lines()
            .filter(|l| !l.starts_with("in `"))
            .collect::<Vec<_>>()
            .join(" ")
            .trim()
            .to_string();
        // A nested deserializer reports its own sub-path as "at `a.b`: ...".
        if let Some(rest) = message.strip_prefix("at `")
            && let Some((sub, msg)) = rest.split_once("`: ")
        {
            let sub = dotted_path(sub);
            path = if path == "." || path.is_empty() {
                sub
            } else {
                format!("{path}.{sub}")
            };
            message = msg.to_string();
        }
        // serde says: unknown variant `mailbx`, expected one of `fifo`, ...
        // for a bad value: the key is the path itself, and the message
        // lists the valid values.
        if let Some(rest) = message.strip_prefix("unknown variant `")
            && let Some((bad, expected)) = unknown_field(&message)
        {
            let key = if path == "." || path.is_empty() {
                "(top level)".to_string()
            } else {
                path
            };
            let listed = rest
                .split_once('`')
                .map(|(_, r)| r.trim_start_matches(',').trim())
                .unwrap_or("");
            let message = format!("unknown value `{bad}`: {listed}");
            let best = closest(&bad, &expected);
            return invalid(src, &key, message, best);
        }
        // serde says: unknown field `refesh`, expected one of `refresh`, `vsync`
        let (key, suggestion) = match unknown_field(&message) {
            Some((bad, expected)) => {
                // The path may or may not already end with the unknown key.
                let key = if path == "." || path.is_empty() {
                    bad.clone()
                } else if path == bad || path.ends_with(&format!(".{bad}")) {
                    path.clone()
                } else {
                    format!("{path}.{bad}")
                };
                (key, closest(&bad, &expected))
            }
            None => (if path == "." { "(top level)".into() } else { path }, None),
        };
        invalid(src, &key, message, suggestion)
    })
}

/// A serde path (`workload.groups[0].count`) in the dotted form of model
/// keys and `--set` (`workload.groups.0.count`), so that its line in the file
/// and the option that set it can be found.
pub fn dotted_path(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for c in path.chars() {
        match c {
            '[' => out.push('.'),
            ']' => {}
            c => out.push(c),
        }
    }
    out.strip_prefix('.').map(str::to_string).unwrap_or(out)
}

/// The candidate closest to a misspelt `bad`, if any is close.
fn closest(bad: &str, candidates: &[String]) -> Option<String> {
    candidates
        .iter()
        .map(|c| (strsim::jaro_winkler(bad, c), c))
        .filter(|(s, _)| *s > 0.7)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c.clone())
}

/// Builds an [`ConfigError::Invalid`] for `key`, finding its line, or the
/// command-line option that set it.
///
/// A value computed from several inputs may name them all, separated by
/// `|` (`workload.gpu|run.frames`): the error blames the first of them that
/// a command-line option (or an experiment) set, since that is the value
/// the user just changed, else the first.
pub fn invalid(src: &ModelSource, key: &str, message: String, suggestion: Option<String>) -> ConfigError {
    let key = if key.contains('|') {
        let mut candidates = key.split('|').map(str::trim).filter(|k| !k.is_empty());
        let first = candidates.clone().next().unwrap_or(key);
        candidates.find(|k| src.override_of(k).is_some()).unwrap_or(first)
    } else {
        key
    };
    let (file, line) = match src.override_of(key) {
        Some(origin) => (format!("value from `{origin}` (applied to {})", src.name), None),
        None => match src.line_of(key) {
            Some(line) => (src.name.clone(), Some(line)),
            None => match super::hardware::hardware_line_of(src, key) {
                Some((file, line)) => (file, Some(line)),
                None => (src.name.clone(), None),
            },
        },
    };
    ConfigError::Invalid {
        file,
        key: key.to_string(),
        line,
        message,
        suggestion,
    }
}

fn unknown_field(msg: &str) -> Option<(String, Vec<String>)> {
    let rest = msg
        .strip_prefix("unknown field `")
        .or_else(|| msg.strip_prefix("unknown variant `"))?;
    let (bad, rest) = rest.split_once('`')?;
    let expected: Vec<String> = rest.split('`').skip(1).step_by(2).map(str::to_string).collect();
    Some((bad.to_string(), expected))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::apply_set;
    use serde::Deserialize;

    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Display {
        refresh: String,
        vsync: bool,
    }
    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct M {
        display: Display,
    }

    #[test]
    fn unknown_key_has_line_and_suggestion() {
        let src = ModelSource::from_text("m.toml", "# model\n[display]\nrefesh = \"60Hz\"\nvsync = true\n");
        let t = src.table().unwrap();
        let e = deserialize::<M>(&t, &src).unwrap_err().to_string();
        assert!(e.contains("m.toml:3"), "{e}");
        assert!(e.contains("display.refesh"), "{e}");
        assert!(e.contains("did you mean `refresh`"), "{e}");
    }

    #[test]
    fn wrong_type_names_key_and_line() {
        let src = ModelSource::from_text("m.toml", "[display]\nrefresh = \"60Hz\"\nvsync = 3\n");
        let e = deserialize::<M>(&src.table().unwrap(), &src).unwrap_err().to_string();
        assert!(e.contains("display.vsync") && e.contains(":3"), "{e}");
    }

    #[test]
    fn malformed_toml_is_reported() {
        let src = ModelSource::from_text("m.toml", "[display\nrefresh = 1");
        let e = src.table().unwrap_err().to_string();
        assert!(e.contains("m.toml") && e.contains("line 1"), "{e}");
    }

    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Group {
        name: String,
        count: u64,
    }
    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Workload {
        groups: Vec<Group>,
    }
    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct W {
        workload: Workload,
    }

    const GROUPS: &str =
        "[workload]\n\n[[workload.groups]]\nname = \"a\"\ncount = 1\n\n[[workload.groups]]\nname = \"b\"\ncount = -2\n";

    #[test]
    fn keys_in_arrays_of_tables_have_dotted_paths_and_lines() {
        let src = ModelSource::from_text("m.toml", GROUPS);
        let e = deserialize::<W>(&src.table().unwrap(), &src).unwrap_err().to_string();
        assert!(e.starts_with("m.toml:9: key `workload.groups.1.count`"), "{e}");
        let src = ModelSource::from_text("m.toml", &GROUPS.replace("count = -2", "cont = 2"));
        let e = deserialize::<W>(&src.table().unwrap(), &src).unwrap_err().to_string();
        assert!(e.starts_with("m.toml:9: key `workload.groups.1.cont`"), "{e}");
        assert!(e.contains("did you mean `count`"), "{e}");
    }

    #[test]
    fn a_set_array_element_is_blamed_on_the_option() {
        let mut src = ModelSource::from_text("m.toml", &GROUPS.replace("count = -2", "count = 2"));
        let mut t = src.table().unwrap();
        apply_set(&mut t, "workload.groups.1.count=-1").unwrap();
        src.note_override("workload.groups.1.count", "--set workload.groups.1.count=-1".into());
        let e = deserialize::<W>(&t, &src).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "value from `--set workload.groups.1.count=-1` (applied to m.toml): key `workload.groups.1.count`"
            ),
            "{e}"
        );
    }

    #[test]
    fn lines_of_quoted_dotted_keys_and_inline_arrays() {
        let src = ModelSource::from_text(
            "e.toml",
            "[set]\n\"run.frames\" = 3\nx.y = 1\n[[check]]\npath = \"p\"\n\n[[check]]\npath = \"q\"\n",
        );
        assert_eq!(src.line_of("set.run.frames"), Some(2));
        assert_eq!(src.line_of("set.x.y"), Some(3));
        assert_eq!(src.line_of("check.1.path"), Some(8));
        assert_eq!(src.line_of("check.1"), Some(7));
        // An entry past the end: the array's first line.
        assert_eq!(src.line_of("check.2"), Some(4));
        assert_eq!(dotted_path("a.b[0].c[12]"), "a.b.0.c.12");
        assert_eq!(dotted_path("[3].x"), "3.x");
    }

    #[test]
    fn an_error_about_a_table_blames_an_option_that_set_a_key_inside_it() {
        let mut src = ModelSource::from_text("m.toml", "[w]\nd = { kind = \"lognormal\", sigma = 1.0 }\n");
        assert_eq!(src.override_of("w.d"), None);
        src.note_override("w.d.sigma", "--set w.d.sigma=100".into());
        assert_eq!(src.override_of("w.d"), Some("--set w.d.sigma=100"));
        assert_eq!(src.override_of("w.d.sigma"), Some("--set w.d.sigma=100"));
        assert_eq!(src.override_of("w.e"), None);
        // A value set as a whole wins over one set inside it.
        src.note_override("w", "--set w={}".into());
        src.note_override("w.d.sigma", "--set w.d.sigma=3".into());
        assert_eq!(src.override_of("w.d"), Some("--set w={}"));
    }

    #[test]
    fn a_value_of_several_keys_blames_the_one_the_user_set() {
        let mut src = ModelSource::from_text("m.toml", "[workload]\ngpu = \"1ms\"\n[run]\nframes = 3\n");
        let e = invalid(&src, "workload.gpu|run.frames", "too long".into(), None).to_string();
        assert!(e.starts_with("m.toml:2: key `workload.gpu`"), "{e}");
        src.note_override("run.frames", "--frames 9".into());
        let e = invalid(&src, "workload.gpu|run.frames", "too long".into(), None).to_string();
        assert!(
            e.starts_with("value from `--frames 9`") && e.contains("key `run.frames`"),
            "{e}"
        );
    }
}
