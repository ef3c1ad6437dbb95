//! Study H2 (sum against max, paper 000 §4.5.1 on a unified GPU) as a
//! device profile predicts it: the extra time of the heavy vertex load with
//! the heavy fragment load, over its extra time with the light one, from
//! four passes of one mesh (vertex loops 0 / V, fragment loops 0 / F).
//! A pure sum of vertex work v and fragment work f gives 1; a pure
//! maximum gives (max(v, f) - f) / v, 0 when the fragment work is the
//! larger. Issue 30
//! asks the H200 profile to predict the 0.940 the H200 measured; the
//! profile fitted without any pass of H2's mesh makes that a prediction.

use serde::{Deserialize, Serialize};

use crate::components::vertex_cache::CachePolicy;
use crate::measure::device_predict::{DevicePass, predict_on_device};
use crate::measure::device_profile::DeviceProfile;
use crate::measure::passes::{PassRow, TargetSize};
use crate::measure::predictions::fit_rows;
use crate::systems::SystemError;
use crate::systems::error::invalid;

/// `[sum_vs_max]` of a `device_predictions` model: H2's four cells.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SumVsMaxConfig {
    /// The mesh the study draws (a generator spec).
    pub mesh: String,
    /// Its target, `WxH`.
    pub size: String,
    /// The heavy vertex load (the light one is 0 loops).
    pub vs_loops: u32,
    /// The heavy fragment load (the light one is 0 loops).
    pub fs_loops: u32,
    /// The ratio the study measured on the device, when known.
    #[serde(default)]
    pub measured: Option<f64>,
}

/// The ratios (`metrics.sum_vs_max`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SumVsMax {
    /// The study's measured ratio (`measured` of the model file).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_study: Option<f64>,
    /// The ratio of the four cells as measured in the pass CSVs, when all
    /// four are there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_rows: Option<f64>,
    /// Predicted by the profile fitted to every row.
    pub predicted: f64,
    /// Predicted by a profile fitted to every row but those of the study's
    /// mesh, when the rest is enough to fit: a mesh the fit has not seen.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_without_mesh: Option<f64>,
}

/// The ratio `(heavy-heavy - light-heavy) / (heavy-light - light-light)`
/// of four cell times indexed `[vertex heavy][fragment heavy]`.
fn ratio(t: [[f64; 2]; 2]) -> f64 {
    (t[1][1] - t[0][1]) / (t[1][0] - t[0][0])
}

impl SumVsMaxConfig {
    fn size(&self) -> Result<TargetSize, SystemError> {
        self.size
            .parse()
            .map_err(|e: crate::measure::passes::BadSize| invalid("sum_vs_max.size", e.to_string()))
    }

    /// The cells' loop counts, `[vertex heavy][fragment heavy]`.
    fn loops(&self, v: usize, f: usize) -> (u32, u32) {
        ([0, self.vs_loops][v], [0, self.fs_loops][f])
    }

    /// The ratio `profile` predicts (`rendersim predict`'s pass times).
    fn predict(&self, profile: &DeviceProfile) -> Result<f64, SystemError> {
        let size = self.size()?;
        let mut t = [[0.0; 2]; 2];
        for (v, row) in t.iter_mut().enumerate() {
            for (f, cell) in row.iter_mut().enumerate() {
                let (vs_loops, fs_loops) = self.loops(v, f);
                let pass = DevicePass {
                    mesh: self.mesh.clone(),
                    size: (size.width, size.height),
                    vs_loops,
                    fs_loops,
                    geometry_only: false,
                    layers: 1,
                    order: crate::measure::DepthOrder::FrontToBack,
                    depth_test: false,
                    draws: 1,
                };
                *cell = predict_on_device(profile, &pass)
                    .map_err(|e| invalid("sum_vs_max", e.to_string()))?
                    .pass_time_ns;
            }
        }
        Ok(ratio(t))
    }

    /// The four cells' measured ratio, when `rows` hold all four (one draw,
    /// not geometry-only).
    fn measured_in(&self, rows: &[PassRow]) -> Result<Option<f64>, SystemError> {
        let size = self.size()?;
        let mut t = [[None; 2]; 2];
        for (v, row) in t.iter_mut().enumerate() {
            for (f, cell) in row.iter_mut().enumerate() {
                let (vs, fs) = self.loops(v, f);
                *cell = rows
                    .iter()
                    .find(|r| {
                        r.mesh == self.mesh
                            && r.size == size
                            && (r.vs_loops, r.fs_loops) == (vs, fs)
                            && !r.geometry_only
                            && r.draws == 1
                    })
                    .map(|r| r.pass_time_ns);
            }
        }
        Ok(match t {
            [[Some(a), Some(b)], [Some(c), Some(d)]] => Some(ratio([[a, b], [c, d]])),
            _ => None,
        })
    }

    /// The ratios: measured (study, rows), predicted by `profile` and by
    /// `profile` with its costs fitted to `rows` without the study's mesh.
    pub fn evaluate(
        &self,
        profile: &DeviceProfile,
        rows: &[PassRow],
        policy: &CachePolicy,
    ) -> Result<SumVsMax, SystemError> {
        if self.vs_loops == 0 || self.fs_loops == 0 {
            return Err(invalid(
                "sum_vs_max",
                format!(
                    "vs_loops = {}, fs_loops = {}: the heavy loads must be at least 1 loop each",
                    self.vs_loops, self.fs_loops
                ),
            ));
        }
        if let Some(m) = self.measured
            && !m.is_finite()
        {
            return Err(invalid("sum_vs_max.measured", format!("{m}: must be a finite number")));
        }
        let others: Vec<PassRow> = rows.iter().filter(|r| r.mesh != self.mesh).cloned().collect();
        let without = fit_rows(&others, policy)
            .ok()
            .map(|costs| {
                self.predict(&DeviceProfile {
                    costs,
                    ..profile.clone()
                })
            })
            .transpose()?;
        Ok(SumVsMax {
            measured_study: self.measured,
            measured_rows: self.measured_in(rows)?,
            predicted: self.predict(profile)?,
            predicted_without_mesh: without,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ratio_is_one_for_a_sum_and_zero_for_a_max() {
        // light-light 1, vertex work 10, fragment work 6.
        assert_eq!(ratio([[1.0, 7.0], [11.0, 17.0]]), 1.0);
        assert_eq!(ratio([[1.0, 7.0], [11.0, 11.0]]), 0.4);
        assert_eq!(ratio([[1.0, 11.0], [11.0, 11.0]]), 0.0);
    }
}
