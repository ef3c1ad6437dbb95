//! Unit tests of `device_profile.rs`.

use super::*;
use proptest::prelude::*;

fn shipped(name: &str) -> (String, PathBuf) {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("models/devices")
        .join(name);
    (std::fs::read_to_string(&path).unwrap(), path)
}

/// The text with the first line starting `key = ` replaced by `line`.
fn edit(text: &str, key: &str, line: &str) -> String {
    let mut done = false;
    text.lines()
        .map(|l| {
            if !done && l.starts_with(&format!("{key} = ")) {
                done = true;
                format!("{line}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect()
}

fn line_of(text: &str, key: &str) -> usize {
    text.lines().position(|l| l.starts_with(&format!("{key} = "))).unwrap() + 1
}

#[test]
fn a_profile_without_the_overlap_reads_as_none() {
    // Profiles written before the shared-core term read with it at 0,
    // and their passes cost what they did: the sum of the sides.
    let (text, path) = shipped("nvidia-h200.toml");
    let old: String = text
        .lines()
        .filter(|l| !l.starts_with("shared_core_overlap = "))
        .map(|l| format!("{l}\n"))
        .collect();
    let p = DeviceProfile::parse(&old, &path).unwrap();
    assert_eq!(p.costs.shared_core_overlap, 0.0);
    let load = PassLoad {
        pixels: 147456.0,
        draws: 1.0,
        vertices: 15570.0,
        vertex_batches: 576.0,
        triangles: 18432.0,
        vs_loops: 67390.0,
        fs_loops: 7681.0,
        coverage: Coverage {
            triangles: 18432,
            drawn_triangles: 18432,
            fragments: 147456,
            quads: 55296,
            warps: 9695,
            ..Coverage::default()
        },
    };
    let c = p.costs.cost(&load);
    assert_eq!(c.overlap_ns, 0.0);
    assert_eq!(
        c.pass_ns,
        p.costs.pass_overhead_ns + c.clear_ns.max(c.geometry_ns) + c.fragment_ns
    );
    // With it: Gl R / (Gl + R) of it taken off, and never below the
    // larger side.
    let with = DeviceProfile::parse(&text, &path).unwrap().costs;
    let k = with.cost(&load);
    let w = with.shared_core_overlap;
    assert!(w > 0.0 && w <= 1.0);
    let want = w * k.vertex_loop_ns * k.fragment_ns / (k.vertex_loop_ns + k.fragment_ns);
    assert!((k.overlap_ns - want).abs() < 1e-6 * want, "{k:?}");
    assert!(k.pass_ns >= k.geometry_ns.max(k.fragment_ns));
}

#[test]
fn the_shipped_profiles_read_and_validate() {
    for name in ["nvidia-h200.toml", "llvmpipe.toml"] {
        let (text, path) = shipped(name);
        let p = DeviceProfile::parse(&text, &path).unwrap();
        p.validate().unwrap();
        // Written again, read back the same.
        let again = DeviceProfile::parse(&p.to_toml(&["x".into()]), &path).unwrap();
        assert_eq!(again, p, "{name}");
    }
}

#[test]
fn bad_values_name_file_line_and_key() {
    let (text, _) = shipped("nvidia-h200.toml");
    let path = Path::new("dev.toml");
    for (key, value, want) in [
        ("worst_pct", "nan", "key `fit.worst_pct`: NaN"),
        ("worst_pct", "inf", "key `fit.worst_pct`: inf"),
        ("median_pct", "-1.0", "key `fit.median_pct`: -1"),
        (
            "p90_pct",
            "0.5",
            "key `fit.p90_pct`: 0.5: must not be below fit.median_pct",
        ),
        ("loo_median_pct", "nan", "key `fit.loo_median_pct`"),
        ("loo_p90_pct", "-inf", "key `fit.loo_p90_pct`"),
        ("rows", "0", "key `fit.rows`: 0"),
        ("rows", "-3", "fit.rows"),
        ("vertex_ns", "nan", "key `costs.vertex_ns`: NaN"),
        ("vertex_ns", "-inf", "key `costs.vertex_ns`"),
        ("fragment_ns", "-1e-9", "key `costs.fragment_ns`"),
        ("shader_cores", "0", "key `device.shader_cores`: 0"),
        ("shader_cores", "4294967295", "key `device.shader_cores`: 4294967295"),
        ("vertex_cache", "\"bogus\"", "key `device.vertex_cache`"),
        (
            "shared_core_overlap",
            "1.5",
            "key `costs.shared_core_overlap`: 1.5: must be at most 1",
        ),
        ("shared_core_overlap", "-0.1", "key `costs.shared_core_overlap`: -0.1"),
        ("shared_core_overlap", "nan", "key `costs.shared_core_overlap`: NaN"),
    ] {
        let bad = edit(&text, key, &format!("{key} = {value}"));
        let line = line_of(&bad, key);
        let e = DeviceProfile::parse(&bad, path).unwrap_err().to_string();
        assert!(e.starts_with(&format!("dev.toml:{line}: ")), "{key} = {value}: {e}");
        assert!(e.contains(want), "{key} = {value}: {want:?} not in {e}");
    }
    // A standard error of no cost, or a bad one.
    let bad = text.replace("[uncertainty]\n", "[uncertainty]\nwarp_ns = 1.0\n");
    let e = DeviceProfile::parse(&bad, path).unwrap_err().to_string();
    assert!(
        e.contains("key `uncertainty.warp_ns`") && e.contains("no cost key"),
        "{e}"
    );
    let (head, tail) = text.split_at(text.find("[uncertainty]").unwrap());
    let bad = format!("{head}{}", edit(tail, "vertex_ns", "vertex_ns = nan"));
    let e = DeviceProfile::parse(&bad, path).unwrap_err().to_string();
    assert!(e.contains("uncertainty.vertex_ns") && e.contains("NaN"), "{e}");
    // Every cost zero: predicts nothing.
    let mut zero = text.clone();
    for (k, _) in DeviceCosts::default().entries() {
        zero = edit(&zero, k, &format!("{k} = 0.0"));
    }
    let e = DeviceProfile::parse(&zero, path).unwrap_err().to_string();
    assert!(e.contains("key `costs`") && e.contains("0 ns for every pass"), "{e}");
    // Syntax and unknown keys: the file and line too.
    let e = DeviceProfile::parse("[device]\nname = \"x\"\n[device]: y\n", path)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("dev.toml: malformed TOML") && e.contains("line 3"), "{e}");
    let e = DeviceProfile::parse(
        &text.replace("vertex_loop_latency_ns", "vertex_loop_latency_nanos"),
        path,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("dev.toml:") && e.contains("costs.vertex_loop_latency_nanos"),
        "{e}"
    );
}

fn profile(name: String, costs: [f64; COSTS], stats: [f64; 3], loo: Option<(f64, f64)>) -> DeviceProfile {
    let mut s = stats;
    s.sort_by(f64::total_cmp);
    let mut costs = costs;
    costs[0] = costs[0].max(1e-3);
    DeviceProfile {
        device: DeviceInfo {
            name,
            vertex_cache: "fifo:32".into(),
            shader_cores: 132,
        },
        costs: DeviceCosts::from_array(&costs),
        uncertainty: DeviceCosts::from_array(&costs)
            .entries()
            .iter()
            .map(|(k, v)| (k.to_string(), v / 3.0))
            .collect(),
        fit: FitAccuracy {
            rows: 95,
            median_pct: s[0],
            p90_pct: s[1],
            worst_pct: s[2],
            loo_median_pct: loo.map(|(a, b)| a.min(b)),
            loo_p90_pct: loo.map(|(a, b)| a.max(b)),
            kfold_median_pct: loo.map(|(a, b)| a.min(b) + 1.0),
            kfold_p90_pct: loo.map(|(a, b)| a.max(b) + 2.0),
        },
    }
}

fn names() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<String>(),
        "[ -~]{0,20}",
        Just("x\n[device]".to_string()),
        Just("quote \" and ' and ''' and \"\"\" and \\ back\\slash".to_string()),
        Just("trailing newline\n".to_string()),
        Just("\r\n\t\u{0}\u{7f}\u{85}\u{2028}\u{feff}".to_string()),
        Just("ünïcødé 🎮 日本語".to_string()),
        Just("\n".to_string()),
        Just(String::new()),
    ]
}

proptest! {
    /// Whatever calibrate writes, `parse` reads back to the same values
    /// (names with newlines, quotes, backslashes, unicode; any finite
    /// non-negative numbers).
    #[test]
    fn what_calibrate_writes_reads_back(
        name in names(),
        costs in proptest::array::uniform15(prop_oneof![Just(0.0), 0.0f64..1e6, 0.0f64..=MAX_COST_NS]),
        stats in proptest::array::uniform3(0.0f64..1e6),
        loo in proptest::option::of((0.0f64..1e6, 0.0f64..1e6)),
    ) {
        let p = profile(name.clone(), costs, stats, loo);
        p.validate().unwrap();
        let header = vec![format!("Device profile {name}: fitted by a test."), "Files: a.csv.".to_string()];
        let text = p.to_toml(&header);
        let back = DeviceProfile::parse(&text, Path::new("p.toml"));
        prop_assert!(back.is_ok(), "{:?}\n{}", back.err().map(|e| e.to_string()), text);
        prop_assert_eq!(back.unwrap(), p);
        // The header stays comment lines.
        prop_assert_eq!(text.lines().take_while(|l| !l.is_empty()).count(), 2, "{}", text);
    }
}
