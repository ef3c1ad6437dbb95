//! Tests for [`super::Dist`].

use super::*;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn rng() -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(0x5eed)
}

fn all_kinds() -> Vec<Dist<f64>> {
    vec![
        Dist::Const { value: 2.5 },
        Dist::Uniform { min: 1.0, max: 4.0 },
        Dist::Exponential { mean: 2.0 },
        Dist::Lognormal {
            median: 1.5,
            sigma: 0.5,
        },
        Dist::Pareto { scale: 1.0, shape: 3.5 },
        Dist::Mixture {
            parts: vec![
                MixturePart {
                    weight: 3.0,
                    dist: Dist::Const { value: 1.0 },
                },
                MixturePart {
                    weight: 1.0,
                    dist: Dist::Exponential { mean: 4.0 },
                },
            ],
        },
    ]
}

fn within_rel(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-9)
}

#[test]
fn sample_means_converge() {
    let mut r = rng();
    for d in all_kinds() {
        d.validate().unwrap();
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| d.sample(&mut r)).collect();
        assert!(xs.iter().all(|x| *x >= 0.0 && x.is_finite()));
        let m = xs.iter().sum::<f64>() / n as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n as f64;
        assert!(within_rel(m, d.mean(), 0.02), "{d:?}: mean {m} vs {}", d.mean());
        if d.variance() > 0.0 {
            assert!(within_rel(v, d.variance(), 0.1), "{d:?}: var {v} vs {}", d.variance());
        } else {
            assert_eq!(v, 0.0);
        }
    }
}

#[test]
fn expected_max_matches_monte_carlo() {
    let mut r = rng();
    for d in all_kinds() {
        let xs: Vec<f64> = (0..200_000).map(|_| d.sample(&mut r)).collect();
        for a in [-1.0, 0.0, 0.5, 1.2, 2.0, 3.0, 6.0] {
            let mc = xs.iter().map(|x| x.max(a)).sum::<f64>() / xs.len() as f64;
            let cf = d.expected_max_with(a);
            assert!(within_rel(cf, mc, 0.02), "{d:?} a={a}: {cf} vs mc {mc}");
            assert!(cf >= a && cf >= d.mean() - 1e-12);
        }
    }
}

#[test]
fn survival_matches_monte_carlo() {
    let mut r = rng();
    for d in all_kinds() {
        let xs: Vec<f64> = (0..200_000).map(|_| d.sample(&mut r)).collect();
        for x in [0.5, 1.2, 2.0, 3.0, 6.0] {
            let mc = xs.iter().filter(|&&v| v > x).count() as f64 / xs.len() as f64;
            let exact = d.survival(x);
            assert!((0.0..=1.0).contains(&exact), "{d:?} at {x}: {exact}");
            // Four standard errors of a proportion from 200,000 draws.
            assert!(
                (mc - exact).abs() < 4.0 * (0.25f64 / 200_000.0).sqrt() + 1e-12,
                "{d:?} at {x}: {mc} vs {exact}"
            );
        }
    }
}

#[test]
fn expected_max_exact_for_const() {
    let d = Dist::Const { value: 3.0 };
    assert_eq!(d.expected_max_with(1.0), 3.0);
    assert_eq!(d.expected_max_with(3.0), 3.0);
    assert_eq!(d.expected_max_with(7.5), 7.5);
}

#[test]
fn heavy_tails_are_infinite() {
    let p = Dist::Pareto { scale: 1.0, shape: 1.0 };
    assert_eq!(p.mean(), f64::INFINITY);
    assert_eq!(p.variance(), f64::INFINITY);
    assert_eq!(p.expected_max_with(2.0), f64::INFINITY);
    let p2 = Dist::Pareto { scale: 1.0, shape: 1.5 };
    assert!(p2.mean().is_finite());
    assert_eq!(p2.variance(), f64::INFINITY);
    let mut r = rng();
    let tiny = Dist::Pareto {
        scale: 1.0,
        shape: 0.001,
    };
    for _ in 0..1000 {
        let x = tiny.sample(&mut r);
        assert!(x.is_finite() && x >= 1.0);
    }
}

#[test]
fn scaled_scales_moments() {
    for d in all_kinds() {
        let s = d.scaled(3.0);
        assert!(within_rel(s.mean(), 3.0 * d.mean(), 1e-12));
        assert!(within_rel(s.variance(), 9.0 * d.variance(), 1e-12));
        assert!(within_rel(
            s.expected_max_with(6.0),
            3.0 * d.expected_max_with(2.0),
            1e-12
        ));
    }
}

#[test]
fn validation_names_the_parameter() {
    let cases: Vec<(Dist<f64>, &str)> = vec![
        (Dist::Const { value: -1.0 }, "value"),
        (Dist::Const { value: f64::NAN }, "value"),
        (
            Dist::Uniform {
                min: 0.0,
                max: f64::INFINITY,
            },
            "max",
        ),
        (Dist::Uniform { min: 2.0, max: 1.0 }, "min"),
        (Dist::Exponential { mean: -0.1 }, "mean"),
        (
            Dist::Lognormal {
                median: 1.0,
                sigma: -1.0,
            },
            "sigma",
        ),
        (
            Dist::Lognormal {
                median: 0.0,
                sigma: 1.0,
            },
            "median",
        ),
        (Dist::Pareto { scale: 1.0, shape: 0.0 }, "shape"),
        (Dist::Pareto { scale: 0.0, shape: 2.0 }, "scale"),
        (Dist::Mixture { parts: vec![] }, "parts"),
        (
            Dist::Mixture {
                parts: vec![MixturePart {
                    weight: 0.0,
                    dist: Dist::Const { value: 1.0 },
                }],
            },
            "parts[0].weight",
        ),
        (
            Dist::Mixture {
                parts: vec![
                    MixturePart {
                        weight: 1.0,
                        dist: Dist::Const { value: 1.0 },
                    },
                    MixturePart {
                        weight: 1.0,
                        dist: Dist::Exponential { mean: f64::NAN },
                    },
                ],
            },
            "parts[1].dist.mean",
        ),
    ];
    for (d, param) in cases {
        let err = d.validate().expect_err(&format!("{d:?} should be invalid"));
        assert!(
            err.to_string().contains(&format!("`{param}")),
            "{err} should name {param}"
        );
    }
}

#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Holder {
    d: Dist<f64>,
}

fn parse(src: &str) -> Result<Dist<f64>, String> {
    toml::from_str::<Holder>(src).map(|h| h.d).map_err(|e| e.to_string())
}

#[test]
fn serde_scalar_and_tables() {
    assert_eq!(parse("d = 3").unwrap(), Dist::Const { value: 3.0 });
    assert_eq!(parse("d = 0.25").unwrap(), Dist::Const { value: 0.25 });
    assert_eq!(
        parse("d = { kind = \"lognormal\", median = 2, sigma = 0.5 }").unwrap(),
        Dist::Lognormal {
            median: 2.0,
            sigma: 0.5
        }
    );
    assert_eq!(
        parse("[d]\nkind = \"const\"\nvalue = 1.5\n").unwrap(),
        Dist::Const { value: 1.5 }
    );
    let m = parse(
        "[d]\nkind = \"mixture\"\n[[d.parts]]\nweight = 1\ndist = 2\n[[d.parts]]\nweight = 2\ndist = { kind = \"pareto\", scale = 1, shape = 2 }\n",
    )
    .unwrap();
    assert_eq!(m.kind(), "mixture");
    // JSON too.
    let j: Dist<f64> = serde_json::from_str(r#"{"kind":"uniform","min":1,"max":2}"#).unwrap();
    assert_eq!(j, Dist::Uniform { min: 1.0, max: 2.0 });
    let j: Dist<f64> = serde_json::from_str("4").unwrap();
    assert_eq!(j, Dist::Const { value: 4.0 });
}

#[test]
fn serde_round_trips_through_toml() {
    for d in all_kinds() {
        let h = Holder { d };
        let text = toml::to_string(&h).unwrap();
        assert!(text.contains("kind"), "{text}");
        let back: Holder = toml::from_str(&text).unwrap();
        assert_eq!(back, h, "{text}");
    }
}

#[test]
fn serde_errors_are_clear() {
    let e = parse("d = { kind = \"gamma\", mean = 1 }").unwrap_err();
    assert!(e.contains("gamma") && e.contains("lognormal"), "{e}");
    let e = parse("d = { kind = \"exponential\", mean = 1, sigma = 2 }").unwrap_err();
    assert!(
        e.contains("`sigma`") && e.contains("exponential") && e.contains("`mean`"),
        "{e}"
    );
    let e = parse("d = { kind = \"uniform\", min = 1, maximum = 2 }").unwrap_err();
    assert!(
        e.contains("unknown field `maximum` for kind `uniform`, expected `min`, `max`"),
        "{e}"
    );
    let e = parse("d = { maximum = 2 }").unwrap_err();
    assert!(e.contains("missing field `kind`"), "{e}");
    let e = parse("d = { kind = \"uniform\", min = 1 }").unwrap_err();
    assert!(e.contains("missing field `max`"), "{e}");
    let e = parse("d = { median = 1 }").unwrap_err();
    assert!(e.contains("missing field `kind`"), "{e}");
    let e = parse("d = true").unwrap_err();
    assert!(e.contains("a constant or a table"), "{e}");
    let e = parse("d = { kind = \"mixture\", parts = [{ weight = 1, dist = 1, extra = 2 }] }").unwrap_err();
    assert!(e.contains("extra"), "{e}");
}
