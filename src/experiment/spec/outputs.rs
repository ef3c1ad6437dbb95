//! What an experiment reports, validated against its sweeps: metrics,
//! derived values, checks and inverse searches (the experiment file's
//! `[[metric]]`, `[[derived]]`, `[[check]]` and `[[search]]` entries; its
//! `[[plot]]`s are in `plots.rs`). Errors name the entry and its key, with
//! the file's line, as everywhere in [`super::validate`].

use super::raw::*;
use super::validate::Validator;
use super::*;
use crate::config::{flatten, flatten_until};
use crate::experiment::ExperimentError;
use crate::experiment::sweep::values_match;

/// Sweep key = value pairs selecting points.
pub(super) type Filter = Vec<(String, toml::Value)>;
impl Validator<'_> {
    /// A `where`-like table of `key` = value: every key a sweep key, every
    /// value one of that sweep's values; flattened to dotted keys, except
    /// below a sweep key, whose value (a table, for a sweep of tables) is
    /// taken whole.
    pub(super) fn filter(
        &self,
        sweeps: &[Sweep],
        key: &str,
        t: &toml::Table,
    ) -> Result<Vec<(String, toml::Value)>, ExperimentError> {
        let mut flat = Vec::new();
        flatten_until("", t, &|k| sweeps.iter().any(|s| s.key == k), &mut flat);
        for (k, v) in &flat {
            let Some(s) = sweeps.iter().find(|s| s.key == *k) else {
                return Err(self.err(key, format!("`{k}` is not a sweep key")));
            };
            if !s.values.iter().any(|sv| values_match(sv, v)) {
                return Err(self.err(key, format!("`{k}` = {v} is not one of the swept values")));
            }
        }
        Ok(flat)
    }

    /// The `[[metric]]`s: summary paths, each listed once.
    pub(super) fn metrics(&self, raw: Vec<RawMetric>) -> Result<Vec<Metric>, ExperimentError> {
        let mut metrics: Vec<Metric> = Vec::new();
        for (i, m) in raw.into_iter().enumerate() {
            if m.path.trim().is_empty() {
                return Err(self.err(format!("metric[{i}].path"), "must not be empty"));
            }
            if metrics.iter().any(|o| o.path == m.path) {
                return Err(self.err(format!("metric[{i}].path"), format!("`{}` is listed twice", m.path)));
            }
            metrics.push(Metric {
                label: m.label.unwrap_or_else(|| m.path.clone()),
                path: m.path,
            });
        }
        Ok(metrics)
    }

    /// The `[[derived]]` values: unique names, each kind with what it needs.
    pub(super) fn derived(
        &self,
        raw: Vec<RawDerived>,
        sweeps: &[Sweep],
        metrics: &[Metric],
    ) -> Result<Vec<Derived>, ExperimentError> {
        let mut derived: Vec<Derived> = Vec::new();
        for (i, d) in raw.into_iter().enumerate() {
            let key = format!("derived[{i}] ({})", d.name);
            if d.name.trim().is_empty() {
                return Err(self.err(format!("derived[{i}].name"), "must not be empty"));
            }
            if derived.iter().any(|o| o.name == d.name) || metrics.iter().any(|m| m.path == d.name) {
                return Err(self.err(&key, format!("name `{}` is already used", d.name)));
            }
            let need_column = || {
                d.column
                    .clone()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `column`", d.kind)))
            };
            let need_path = || {
                d.path
                    .clone()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `path`", d.kind)))
            };
            let need_ref = || -> Result<Vec<(String, toml::Value)>, ExperimentError> {
                let r = d
                    .reference
                    .as_ref()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `reference`", d.kind)))?;
                let r = self.filter(sweeps, &format!("{key}.reference"), r)?;
                if r.is_empty() {
                    return Err(self.err(format!("{key}.reference"), "must name at least one sweep key"));
                }
                Ok(r)
            };
            let kind = match d.kind.as_str() {
                "interval_width" => {
                    let level = d.level.ok_or_else(|| self.err(&key, "needs `level`"))?;
                    if !(level > 0.0 && level < 1.0) {
                        return Err(self.err(format!("{key}.level"), "must be in (0, 1)"));
                    }
                    DerivedKind::IntervalWidth {
                        column: need_column()?,
                        level,
                    }
                }
                "quantile_width_from_min" => {
                    let level = d.level.ok_or_else(|| self.err(&key, "needs `level`"))?;
                    if !(level > 0.0 && level <= 1.0) {
                        return Err(self.err(format!("{key}.level"), "must be in (0, 1]"));
                    }
                    DerivedKind::QuantileWidthFromMin {
                        column: need_column()?,
                        level,
                    }
                }
                "modes" | "largest_bin_share" => {
                    let bin = d
                        .bin
                        .ok_or_else(|| self.err(&key, format!("kind `{}` needs `bin`", d.kind)))?;
                    if !(bin.is_finite() && bin > 0.0) {
                        return Err(self.err(format!("{key}.bin"), format!("must be finite and > 0, got {bin}")));
                    }
                    if d.kind == "modes" {
                        let prominence = d.prominence.unwrap_or(0.1);
                        if !(prominence > 0.0 && prominence <= 1.0) {
                            return Err(self.err(
                                format!("{key}.prominence"),
                                format!("must be in (0, 1], got {prominence}"),
                            ));
                        }
                        DerivedKind::Modes {
                            column: need_column()?,
                            bin,
                            prominence,
                        }
                    } else {
                        if d.prominence.is_some() {
                            return Err(self.err(format!("{key}.prominence"), "applies only to kind `modes`"));
                        }
                        DerivedKind::LargestBinShare {
                            column: need_column()?,
                            bin,
                        }
                    }
                }
                "relative_error" => DerivedKind::RelativeError {
                    path: need_path()?,
                    reference: need_ref()?,
                },
                "ratio" => DerivedKind::Ratio {
                    path: need_path()?,
                    reference: need_ref()?,
                },
                "speedup" => DerivedKind::Speedup {
                    path: d.path.clone().unwrap_or_else(|| "wall_seconds".into()),
                    reference: need_ref()?,
                },
                other => {
                    return Err(self.err(
                        format!("{key}.kind"),
                        format!(
                            "unknown kind `{other}` (expected interval_width, quantile_width_from_min, modes, largest_bin_share, relative_error, ratio or speedup)"
                        ),
                    ));
                }
            };
            let label = match d.label {
                Some(l) if l.trim().is_empty() => {
                    return Err(self.err(format!("{key}.label"), "must not be empty"));
                }
                Some(l) => l,
                None => d.name.clone(),
            };
            derived.push(Derived {
                name: d.name,
                label,
                kind,
            });
        }
        Ok(derived)
    }

    /// The `[[check]]`s: a path, a tolerance, and an expected value or
    /// bounds (numbers or other paths), with an optional claim.
    pub(super) fn checks(&self, raw: Vec<RawCheck>, sweeps: &[Sweep]) -> Result<Vec<Check>, ExperimentError> {
        let mut checks = Vec::new();
        for (i, c) in raw.into_iter().enumerate() {
            let key = format!("check[{i}] ({})", c.path);
            if c.path.trim().is_empty() {
                return Err(self.err(format!("check[{i}].path"), "must not be empty"));
            }
            let tolerance = match (c.tolerance, c.rel_tolerance) {
                (Some(t), None) => Tolerance::Absolute(t),
                (None, Some(t)) => Tolerance::Relative(t),
                _ => {
                    return Err(self.err(&key, "give exactly one of `tolerance` and `rel_tolerance`"));
                }
            };
            let (Tolerance::Absolute(t) | Tolerance::Relative(t)) = tolerance;
            if !(t >= 0.0 && t.is_finite()) {
                return Err(self.err(&key, "tolerance must be a finite number >= 0"));
            }
            let bound = |b: Option<String>, name: &str| match b {
                Some(b) if b.trim().is_empty() => Err(self.err(format!("{key}.{name}"), "must not be empty")),
                other => Ok(other),
            };
            let number = |v: Option<f64>, name: &str| match v {
                Some(v) if !v.is_finite() => Err(self.err(format!("{key}.{name}"), "must be finite")),
                other => Ok(other.map(BoundRef::Value)),
            };
            let either = |p: Option<String>, v: Option<BoundRef>, name: &str| match (p, v) {
                (Some(_), Some(_)) => Err(self.err(&key, format!("give either `{name}_path` or `{name}`, not both"))),
                (Some(p), None) => Ok(Some(BoundRef::Path(p))),
                (None, v) => Ok(v),
            };
            let at_least = either(
                bound(c.at_least_path, "at_least_path")?,
                number(c.at_least, "at_least")?,
                "at_least",
            )?;
            let at_most = either(
                bound(c.at_most_path, "at_most_path")?,
                number(c.at_most, "at_most")?,
                "at_most",
            )?;
            if let (Some(BoundRef::Value(lo)), Some(BoundRef::Value(hi))) = (&at_least, &at_most)
                && lo > hi
            {
                return Err(self.err(&key, format!("`at_least` = {lo} is above `at_most` = {hi}")));
            }
            if let Some(text) = &c.claim
                && text.trim().is_empty()
            {
                return Err(self.err(format!("{key}.claim"), "must not be empty"));
            }
            let expect = match (c.expect, at_least.is_some() || at_most.is_some()) {
                (Some(_), true) => {
                    return Err(self.err(
                        &key,
                        "give either `expect` or bounds (`at_least[_path]`/`at_most[_path]`), not both",
                    ));
                }
                (None, false) => {
                    return Err(self.err(
                        &key,
                        "needs `expect` or `at_least_path`/`at_most_path` (or `at_least`/`at_most`)",
                    ));
                }
                (Some(v), false) => {
                    if !v.is_finite() {
                        return Err(self.err(format!("{key}.expect"), "must be finite"));
                    }
                    Expect::Value(v)
                }
                (None, true) => Expect::Between { at_least, at_most },
            };
            checks.push(Check {
                filter: self.filter(sweeps, &format!("{key}.where"), &c.filter)?,
                path: c.path,
                expect,
                tolerance,
                claim: c.claim,
            });
        }
        Ok(checks)
    }

    /// The `[[search]]`es, each under its own name.
    ///
    /// A search's `path` may name a derived value of a frame column
    /// (`interval_width`, `quantile_width_from_min`, `modes`,
    /// `largest_bin_share`): each run of the search then keeps its frames
    /// and the value is computed from them, as for a point. A derived value
    /// taken between points (`ratio` and the like) has no meaning for one
    /// run and is refused.
    pub(super) fn searches(
        &self,
        raw: Vec<crate::experiment::inverse::RawSearch>,
        derived: &[super::Derived],
    ) -> Result<Vec<crate::experiment::inverse::Search>, ExperimentError> {
        let mut searches = Vec::new();
        for (i, r) in raw.into_iter().enumerate() {
            let flat = |t: &toml::Table| {
                let mut v = Vec::new();
                flatten("", t, &mut v);
                v
            };
            let mut sp = crate::experiment::inverse::validate(r, flat)
                .map_err(|(k, m)| self.err(format!("search[{i}].{k}"), m))?;
            if let Some(d) = derived.iter().find(|d| d.name == sp.path) {
                if d.kind.frame_column().is_none() {
                    return Err(self.err(
                        format!("search[{i}].path"),
                        format!(
                            "`{}` is a derived value taken between points; a search reaches a summary metric \
                             or a derived value of a frame column (interval_width, quantile_width_from_min, \
                             modes, largest_bin_share)",
                            sp.path
                        ),
                    ));
                }
                sp.frame_value = Some(d.kind.clone());
            }
            if searches
                .iter()
                .any(|o: &crate::experiment::inverse::Search| o.name == sp.name)
            {
                return Err(self.err(format!("search[{i}].name"), format!("`{}` is used twice", sp.name)));
            }
            searches.push(sp);
        }
        Ok(searches)
    }
}
