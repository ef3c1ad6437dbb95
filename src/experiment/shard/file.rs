//! The shard file's format (see the parent module): what a shard writes
//! (its runs with their numbers as shortest round-trip text, their
//! checksum, the experiment's fingerprint and the version), and how a file
//! is read back and checked against the shard it should be.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::super::ExperimentError;
use super::super::results::{JobOutput, RunRecord};
use super::{SHARD_FORMAT, ShardId, VERSION};

/// One shard file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShardFile {
    pub(super) format: String,
    pub(super) rendersim_version: String,
    pub(super) experiment: String,
    pub(super) experiment_hash: String,
    pub(super) shard: usize,
    pub(super) shards: usize,
    /// Runs of the whole experiment.
    pub(super) total_runs: usize,
    /// Wall clock at the shard's start and end, seconds since the Unix epoch.
    pub(super) started_unix: f64,
    pub(super) finished_unix: f64,
    /// CPU time of the shard's process (user + system), seconds.
    pub(super) cpu_seconds: f64,
    /// SHA-256 of `runs` as JSON text ([`runs_checksum`]): a file whose runs
    /// were edited after it was written is not taken as complete.
    pub(super) runs_sha256: String,
    pub(super) runs: Vec<ShardRun>,
}

/// The checksum stored with a shard's runs: SHA-256 of their JSON text.
pub(super) fn runs_checksum(runs: &[ShardRun]) -> String {
    // Serializing strings and integers cannot fail.
    let text = serde_json::to_vec(runs).unwrap_or_default();
    super::super::fingerprint::sha256_hex(&text)
}

/// One run in a shard file. Floats are text (see the module documentation).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShardRun {
    pub(super) point: usize,
    pub(super) seed: u64,
    /// Tracked path values, space-separated; `null` for a JSON null.
    pub(super) values: String,
    pub(super) wall_seconds: String,
    /// One space-separated column per frame column.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) frames: Vec<String>,
}

pub(super) fn float_text(x: f64) -> String {
    format!("{x:e}")
}

pub(super) fn floats_text(v: &[f64]) -> String {
    let mut s = String::with_capacity(v.len() * 12);
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        s.push_str(&float_text(*x));
    }
    s
}

/// A tracked value or a time read back: a finite number.
pub(super) fn parse_float(t: &str) -> Result<f64, String> {
    match t.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("`{t}` is not a finite number")),
        Err(_) => Err(format!("`{t}` is not a number")),
    }
}

/// A per-frame value read back: a finite number, or `NaN`, which the
/// systems' tables use for a value a frame does not have.
pub(super) fn parse_frame_value(t: &str) -> Result<f64, String> {
    if t == "NaN" {
        return Ok(f64::NAN);
    }
    parse_float(t)
}

impl ShardRun {
    pub(super) fn from_output(o: &JobOutput) -> ShardRun {
        let values = o
            .record
            .values
            .iter()
            .map(|v| v.map_or_else(|| "null".to_string(), float_text))
            .collect::<Vec<_>>()
            .join(" ");
        ShardRun {
            point: o.record.point,
            seed: o.record.seed,
            values,
            wall_seconds: float_text(o.record.wall_seconds),
            frames: o.frames.iter().map(|c| floats_text(c)).collect(),
        }
    }

    pub(super) fn to_output(&self, paths: usize, columns: usize) -> Result<JobOutput, String> {
        let values = self
            .values
            .split_ascii_whitespace()
            .map(|t| {
                if t == "null" {
                    Ok(None)
                } else {
                    parse_float(t).map(Some)
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        if values.len() != paths {
            return Err(format!("{} values where the experiment tracks {paths}", values.len()));
        }
        if self.frames.len() != columns {
            return Err(format!(
                "{} frame columns where the experiment needs {columns}",
                self.frames.len()
            ));
        }
        let frames = self
            .frames
            .iter()
            .map(|c| c.split_ascii_whitespace().map(parse_frame_value).collect())
            .collect::<Result<Vec<Vec<f64>>, _>>()?;
        if let Some(first) = frames.first()
            && let Some(other) = frames.iter().find(|c| c.len() != first.len())
        {
            return Err(format!(
                "frame columns of {} and {} values: every column has one value per frame",
                first.len(),
                other.len()
            ));
        }
        let wall_seconds = parse_float(&self.wall_seconds)?;
        if wall_seconds < 0.0 {
            return Err(format!("wall_seconds `{}` is negative", self.wall_seconds));
        }
        Ok(JobOutput {
            record: RunRecord {
                point: self.point,
                seed: self.seed,
                values,
                wall_seconds,
            },
            frames,
        })
    }
}

pub(super) fn shard_error(file: &Path, message: impl Into<String>) -> ExperimentError {
    ExperimentError::Shard {
        file: file.to_path_buf(),
        message: message.into(),
    }
}

pub(super) fn read_shard(path: &Path) -> Result<ShardFile, ExperimentError> {
    let text =
        crate::limits::read_input(path, crate::limits::InputKind::Text).map_err(|source| ExperimentError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    let file: ShardFile =
        serde_json::from_slice(&text).map_err(|e| shard_error(path, format!("not a readable shard file ({e})")))?;
    if file.format != SHARD_FORMAT {
        return Err(shard_error(
            path,
            format!("format `{}`, expected `{SHARD_FORMAT}`", file.format),
        ));
    }
    for (key, x) in [
        ("started_unix", file.started_unix),
        ("finished_unix", file.finished_unix),
        ("cpu_seconds", file.cpu_seconds),
    ] {
        if !x.is_finite() || x < 0.0 {
            return Err(shard_error(path, format!("`{key}` is {x}: not a finite time")));
        }
    }
    if file.finished_unix < file.started_unix {
        return Err(shard_error(path, "`finished_unix` is before `started_unix`"));
    }
    Ok(file)
}

/// Why `file` cannot stand for shard `id` of the experiment with `hash`
/// (`None`: it can). Runs are compared with `expected`.
pub(super) fn mismatch(
    file: &ShardFile,
    hash: &str,
    id: Option<ShardId>,
    expected: Option<&[(usize, u64)]>,
) -> Option<String> {
    if file.rendersim_version != VERSION {
        return Some(format!(
            "made by rendersim {}, this is rendersim {VERSION}; rerun the shard with this version",
            file.rendersim_version
        ));
    }
    if file.experiment_hash != hash {
        return Some(format!(
            "made from a different experiment (fingerprint {}..., this experiment's is {}...): the \
             experiment file or its model changed since the shard ran; rerun the shard",
            &file.experiment_hash.get(..12).unwrap_or(&file.experiment_hash),
            &hash[..12]
        ));
    }
    if let Some(id) = id
        && (file.shard != id.k || file.shards != id.n)
    {
        return Some(format!("holds shard {}/{}, not {id}", file.shard, file.shards));
    }
    if runs_checksum(&file.runs) != file.runs_sha256 {
        return Some(
            "its runs do not match the checksum stored with them (`runs_sha256`): the file was edited or damaged \
             after it was written; rerun the shard"
                .into(),
        );
    }
    if let Some(expected) = expected {
        let got: Vec<(usize, u64)> = file.runs.iter().map(|r| (r.point, r.seed)).collect();
        if got != expected {
            return Some(format!(
                "holds {} runs where shard {}/{} has {} (or other runs): incomplete or damaged",
                got.len(),
                file.shard,
                file.shards,
                expected.len()
            ));
        }
    }
    None
}
