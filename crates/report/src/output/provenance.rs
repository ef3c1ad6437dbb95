//! Where a result came from: the program's version, the git revision it was
//! built from (when known), the command that made the result, and the date.
//!
//! The same record is written three ways, one writer each: a `provenance`
//! object in JSON summaries, a `## Provenance` section in Markdown reports,
//! and comment lines at the head of a TOML model. It is the one part of an
//! output that changes from run to run with the same seed; set
//! `SOURCE_DATE_EPOCH` (seconds since 1970, the reproducible-builds
//! convention) to fix its date.

use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

/// Where a result came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Provenance {
    /// The program and its version, e.g. `rendersim 0.1.0`.
    pub program: String,
    /// The git revision the program was built from (`-dirty` when the tree
    /// had changes), `None` when it was built outside a git checkout.
    pub git_revision: Option<String>,
    /// The command that made the result, one argument a string.
    pub command: Vec<String>,
    /// When, in UTC (RFC 3339, whole seconds).
    pub date: String,
}

impl Provenance {
    /// A record dated now (or at `SOURCE_DATE_EPOCH` when that is set to a
    /// whole number of seconds; at 0, 1970-01-01, under `--no-timing`
    /// without it, so that outputs compare byte for byte:
    /// [`super::timing`]).
    pub fn now(program: impl Into<String>, git_revision: Option<String>, command: Vec<String>) -> Self {
        let no_timing = std::env::var_os("RENDERSIM_NO_TIMING").is_some_and(|v| !v.is_empty());
        let secs = std::env::var("SOURCE_DATE_EPOCH")
            .ok()
            .and_then(|s| s.trim().parse::<i64>().ok())
            .unwrap_or_else(|| {
                if no_timing {
                    return 0;
                }
                SystemTime::now()
                    .duration_since(UNIX_EPOCH)
                    .map_or(0, |d| d.as_secs() as i64)
            });
        Self {
            program: program.into(),
            git_revision,
            command,
            date: rfc3339_utc(secs),
        }
    }

    /// The command as one line a shell would read back the same way.
    pub fn command_line(&self) -> String {
        self.command
            .iter()
            .map(|a| shell_quote(a))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The program and revision in a few words: `rendersim 0.1.0 (git 1a2b3c4d5e6f)`.
    pub fn built(&self) -> String {
        match &self.git_revision {
            Some(rev) => format!("{} (git {rev})", self.program),
            None => format!("{} (git revision unknown)", self.program),
        }
    }

    /// Comment lines for the head of a TOML file (each starts with `# `).
    pub fn toml_comment(&self) -> String {
        format!(
            "# Written by {}, {}\n# Command: {}\n",
            self.built(),
            self.date,
            one_line(&self.command_line())
        )
    }

    /// A Markdown section, `## Provenance`, ending with a blank line.
    pub fn markdown_section(&self) -> String {
        format!(
            "## Provenance\n\n- program: {}\n- git revision: {}\n- command: `{}`\n- date: {}\n\n",
            self.program,
            self.git_revision.as_deref().unwrap_or("unknown"),
            one_line(&self.command_line()).replace('`', "'"),
            self.date
        )
    }
}

/// Newlines in an argument would end a comment line or a list item early.
fn one_line(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

/// `arg` quoted for a POSIX shell when it needs it.
fn shell_quote(arg: &str) -> String {
    let plain = !arg.is_empty()
        && arg
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

/// Seconds since 1970 as `YYYY-MM-DDTHH:MM:SSZ` (proleptic Gregorian, UTC).
pub fn rfc3339_utc(secs: i64) -> String {
    let days = secs.div_euclid(86_400);
    let rem = secs.rem_euclid(86_400);
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The calendar date of a day count since 1970-01-01 (H. Hinnant's
/// `civil_from_days`, exact over the whole `i64` day range used here).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (if m <= 2 { y + 1 } else { y }, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_match_known_calendar_days() {
        assert_eq!(rfc3339_utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339_utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(rfc3339_utc(1_709_251_199), "2024-02-29T23:59:59Z");
        assert_eq!(rfc3339_utc(1_796_386_922), "2026-12-04T12:22:02Z");
        assert_eq!(rfc3339_utc(-1), "1969-12-31T23:59:59Z");
        assert_eq!(rfc3339_utc(4_102_444_800), "2100-01-01T00:00:00Z");
    }

    #[test]
    fn every_day_of_four_centuries_follows_the_one_before() {
        // Day by day from 1900 to 2300: the date advances by exactly one
        // calendar day, months have their lengths, leap years their 29th.
        let mut prev = civil_from_days(-25_567); // 1900-01-01
        assert_eq!(prev, (1900, 1, 1));
        for z in -25_566..120_000 {
            let (y, m, d) = civil_from_days(z);
            let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
            let len = [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31][prev.1 as usize - 1];
            let expect = if prev.2 < len {
                (prev.0, prev.1, prev.2 + 1)
            } else if prev.1 < 12 {
                (prev.0, prev.1 + 1, 1)
            } else {
                (prev.0 + 1, 1, 1)
            };
            assert_eq!((y, m, d), expect, "day {z}");
            prev = (y, m, d);
        }
    }

    #[test]
    fn command_lines_quote_what_a_shell_would_split() {
        let p = Provenance {
            program: "rendersim 0.1.0".into(),
            git_revision: None,
            command: ["rendersim", "run", "--set", "display.mode=\"fifo\"", "a b", "it's", ""]
                .map(String::from)
                .to_vec(),
            date: rfc3339_utc(0),
        };
        assert_eq!(
            p.command_line(),
            r#"rendersim run --set 'display.mode="fifo"' 'a b' 'it'\''s' ''"#
        );
        assert!(p.toml_comment().lines().all(|l| l.starts_with("# ")));
        assert!(p.markdown_section().starts_with("## Provenance\n\n"));
        assert!(p.markdown_section().contains("git revision: unknown"));
    }

    #[test]
    fn newlines_in_an_argument_stay_inside_the_comment() {
        let p = Provenance::now("x 1", Some("abc".into()), vec!["x".into(), "a\nb = 1".into()]);
        let c = p.toml_comment();
        assert_eq!(c.lines().count(), 2, "{c}");
        assert!(c.lines().all(|l| l.starts_with("# ")), "{c}");
        assert!(toml::from_str::<toml::Table>(&c).unwrap().is_empty());
    }
}
