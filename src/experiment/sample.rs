//! Sampled designs: instead of the cartesian product of sweeps, an
//! experiment can draw its points from parameter ranges (`[sample]`).
//!
//! - `latin_hypercube` (McKay, Beckman and Conover 1979): `n` points; each
//!   parameter's range is cut into `n` strata of equal probability and every
//!   stratum holds exactly one point, at a uniform position inside it, the
//!   strata of different parameters paired by independent random
//!   permutations.
//! - `sobol`: Saltelli's scheme for Sobol' indices (Saltelli et al. 2010,
//!   "Variance based sensitivity analysis of model output", §3) on a
//!   Sobol' sequence, as SALib's Saltelli sampler does: the first `n`
//!   points of the `2k`-dimensional Sobol' sequence
//!   ([`super::sobol_sequence`], Joe and Kuo's direction numbers) give two
//!   `n x k` matrices, `A` (its first `k` columns) and `B` (the last `k`),
//!   and for each parameter `i`, `A_B^(i)` is `A` with column `i` taken
//!   from `B`. Points are `A`, then `B`, then `A_B^(1)` .. `A_B^(k)`:
//!   `n (k + 2)` in all; the indices are computed by [`super::sobol`].
//!   With `scramble = true` (the default) the sequence gets a random
//!   digital shift drawn from the seed; `false` gives the plain sequence,
//!   the same points as SciPy's `qmc.Sobol(2k, scramble=False)`. The
//!   sequence is balanced at powers of two: `n` = 2^m is best. At most
//!   [`MAX_SOBOL_PARAMS`] parameters.
//!
//! A parameter maps a unit coordinate `u` in `[0, 1)` to its range:
//! linearly or logarithmically; integers take every value of `from..=to`
//! with equal probability (on a log scale, rounded); a `unit` makes the
//! value a string such as `"12.5ms"`. Draws come from the named RNG
//! stream `sample` of the sample's `seed`, so the same file gives the same
//! points.

use rand::Rng;

use crate::engine::rng::RngStreams;

use super::sweep::format_range_number;

/// How points are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleMethod {
    /// `n` points of a Latin hypercube.
    LatinHypercube,
    /// Saltelli's `n (k + 2)` points on a Sobol' sequence, analysed for
    /// Sobol' indices.
    Sobol,
}

/// Parameters a `sobol` sample can have: two sequence dimensions each.
pub const MAX_SOBOL_PARAMS: usize = super::sobol_sequence::MAX_DIMENSIONS / 2;

/// How a parameter's range is covered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Evenly.
    Linear,
    /// Evenly in the logarithm (`from > 0`).
    Log,
}

/// One sampled model key and its range.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleParam {
    /// Dotted model key.
    pub key: String,
    /// Lower end.
    pub from: f64,
    /// Upper end (`> from`).
    pub to: f64,
    /// Linear or logarithmic.
    pub scale: Scale,
    /// Whole numbers only (`from..=to`).
    pub integer: bool,
    /// Unit appended to the number (the value is then a string, e.g. `ms`).
    pub unit: Option<String>,
}

impl SampleParam {
    /// The number at unit coordinate `u` in `[0, 1)`.
    pub fn number(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        match (self.scale, self.integer) {
            (Scale::Linear, false) => self.from + (self.to - self.from) * u,
            (Scale::Log, false) => self.from * (self.to / self.from).powf(u),
            (Scale::Linear, true) => {
                let span = self.to - self.from + 1.0;
                (self.from + (u * span).floor()).min(self.to)
            }
            (Scale::Log, true) => {
                // Even in log over [from - 0.5, to + 0.5), then rounded.
                let (lo, hi) = ((self.from - 0.5).max(self.from * 0.5), self.to + 0.5);
                (lo * (hi / lo).powf(u)).round().clamp(self.from, self.to)
            }
        }
    }

    /// The model value for `number`: an integer, a float, or a string with the unit.
    pub fn value(&self, number: f64) -> toml::Value {
        match &self.unit {
            Some(unit) => toml::Value::String(format!("{}{unit}", format_range_number(number))),
            None if self.integer => toml::Value::Integer(number as i64),
            None => toml::Value::Float(number),
        }
    }
}

/// A `[sample]` design.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Latin hypercube or Sobol' (Saltelli).
    pub method: SampleMethod,
    /// Base sample size.
    pub n: usize,
    /// Seed of the draws (and of the bootstrap).
    pub seed: u64,
    /// Bootstrap resamples for the confidence intervals of Sobol' indices.
    pub bootstrap: usize,
    /// `sobol`: a random digital shift of the sequence (from `seed`).
    pub scramble: bool,
    /// The parameters, in file order.
    pub params: Vec<SampleParam>,
}

/// `n` rows of a `d`-dimensional Latin hypercube in `[0, 1)^d`.
pub fn latin_hypercube(n: usize, d: usize, rng: &mut impl Rng) -> Vec<Vec<f64>> {
    let mut rows = vec![vec![0.0; d]; n];
    for j in 0..d {
        let mut strata: Vec<usize> = (0..n).collect();
        // Fisher-Yates.
        for i in (1..n).rev() {
            let k = rng.random_range(0..=i);
            strata.swap(i, k);
        }
        for (row, s) in rows.iter_mut().zip(strata) {
            row[j] = (s as f64 + rng.random::<f64>()) / n as f64;
        }
    }
    rows
}

impl Sample {
    /// Points of the design: `n` for a Latin hypercube, `n (k + 2)` for Sobol'.
    pub fn points(&self) -> usize {
        match self.method {
            SampleMethod::LatinHypercube => self.n,
            SampleMethod::Sobol => self.n * (self.params.len() + 2),
        }
    }

    /// The unit coordinates of every point, in point order (see the module
    /// documentation).
    pub fn unit_rows(&self) -> Vec<Vec<f64>> {
        let k = self.params.len();
        let mut rng = RngStreams::new(self.seed).stream("sample");
        match self.method {
            SampleMethod::LatinHypercube => latin_hypercube(self.n, k, &mut rng),
            SampleMethod::Sobol => {
                let shift: Vec<u32> = (0..2 * k)
                    .map(|_| if self.scramble { rng.random::<u32>() } else { 0 })
                    .collect();
                let ab = super::sobol_sequence::sobol_points(self.n, 2 * k, &shift);
                let a: Vec<Vec<f64>> = ab.iter().map(|r| r[..k].to_vec()).collect();
                let b: Vec<Vec<f64>> = ab.iter().map(|r| r[k..].to_vec()).collect();
                let mut rows = a.clone();
                rows.extend(b.iter().cloned());
                for i in 0..k {
                    rows.extend(a.iter().zip(&b).map(|(ra, rb)| {
                        let mut r = ra.clone();
                        r[i] = rb[i];
                        r
                    }));
                }
                rows
            }
        }
    }

    /// `(key, value)` assignments of every point, in point order.
    pub fn assignments(&self) -> Vec<Vec<(String, toml::Value)>> {
        self.unit_rows()
            .iter()
            .map(|row| {
                self.params
                    .iter()
                    .zip(row)
                    .map(|(p, &u)| (p.key.clone(), p.value(p.number(u))))
                    .collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(scale: Scale, integer: bool, from: f64, to: f64) -> SampleParam {
        SampleParam {
            key: "k".into(),
            from,
            to,
            scale,
            integer,
            unit: None,
        }
    }

    #[test]
    fn a_latin_hypercube_has_one_point_per_stratum() {
        let mut rng = RngStreams::new(3).stream("t");
        let rows = latin_hypercube(50, 4, &mut rng);
        for j in 0..4 {
            let mut strata: Vec<usize> = rows.iter().map(|r| (r[j] * 50.0).floor() as usize).collect();
            strata.sort();
            assert_eq!(strata, (0..50).collect::<Vec<_>>());
        }
    }

    #[test]
    fn ranges_map_as_declared() {
        let lin = param(Scale::Linear, false, 2.0, 12.0);
        assert_eq!(lin.number(0.0), 2.0);
        assert_eq!(lin.number(0.5), 7.0);
        let log = param(Scale::Log, false, 1.0, 100.0);
        assert!((log.number(0.5) - 10.0).abs() < 1e-9);
        let int = param(Scale::Linear, true, 1.0, 4.0);
        let counts = (0..400).fold([0; 4], |mut c, i| {
            c[int.number((i as f64 + 0.5) / 400.0) as usize - 1] += 1;
            c
        });
        assert_eq!(counts, [100; 4], "every integer equally likely");
        let ilog = param(Scale::Log, true, 1.0, 8.0);
        assert!((0..100).all(|i| (1.0..=8.0).contains(&ilog.number(i as f64 / 100.0))));
        let ms = SampleParam {
            unit: Some("ms".into()),
            ..lin
        };
        assert_eq!(ms.value(ms.number(0.25)), toml::Value::String("4.5ms".into()));
        assert_eq!(int.value(3.0), toml::Value::Integer(3));
    }

    #[test]
    fn saltelli_points_share_columns_as_the_scheme_says() {
        let s = Sample {
            method: SampleMethod::Sobol,
            n: 8,
            seed: 5,
            bootstrap: 10,
            scramble: true,
            params: vec![param(Scale::Linear, false, 0.0, 1.0); 3],
        };
        let rows = s.unit_rows();
        assert_eq!(rows.len(), s.points());
        assert_eq!(rows.len(), 8 * 5);
        let (a, b) = (&rows[..8], &rows[8..16]);
        for i in 0..3 {
            let ab = &rows[16 + 8 * i..24 + 8 * i];
            for j in 0..8 {
                for c in 0..3 {
                    assert_eq!(ab[j][c], if c == i { b[j][c] } else { a[j][c] });
                }
            }
        }
        assert_eq!(rows, s.unit_rows(), "same seed, same points");
        // A and B are the two halves of one 6-dimensional Sobol' sequence:
        // unscrambled, exactly SciPy's `qmc.Sobol(6, scramble=False)` points.
        let plain = Sample {
            scramble: false,
            ..s.clone()
        };
        let rows = plain.unit_rows();
        let seq = crate::experiment::sobol_sequence::sobol_points(8, 6, &[0; 6]);
        for j in 0..8 {
            assert_eq!(rows[j], seq[j][..3]);
            assert_eq!(rows[8 + j], seq[j][3..]);
        }
        assert_eq!(rows[1], [0.5, 0.5, 0.5]);
        // Another seed shifts the points, and each column stays balanced:
        // one point in each eighth of [0, 1).
        let other = Sample { seed: 6, ..s.clone() }.unit_rows();
        assert_ne!(other, s.unit_rows());
        for c in 0..3 {
            let mut cells: Vec<usize> = other[..8].iter().map(|r| (r[c] * 8.0) as usize).collect();
            cells.sort();
            assert_eq!(cells, (0..8).collect::<Vec<_>>());
        }
    }
}
