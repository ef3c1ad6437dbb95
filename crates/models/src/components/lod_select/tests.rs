//! Unit tests of LOD selection: a hand-worked instance and the edges.

use super::file::{parse_instance, parse_instance_json};
use super::*;

fn lv(ms: u64, benefit: f64) -> Level {
    Level {
        cost: Duration::ms(ms),
        benefit,
    }
}

fn obj(name: &str, levels: Vec<Level>) -> LodObject {
    LodObject {
        name: name.into(),
        levels,
    }
}

/// Budget 10 ms. Values: A0 4/2 = 2, A1 7/5 = 1.4, B0 3/3 = 1, B1 9/6 =
/// 1.5, C0 6/4 = 1.5. Greedy order: A0, B1 (1.5, benefit 9), C0 (1.5,
/// benefit 6), A1, B0. It takes A0 (8 ms left), B1 (2 ms left); C0 does
/// not fit; A and B have theirs. Optimal: B1 + C0 = 10 ms, benefit 15.
fn hand() -> Instance {
    Instance::new(
        Duration::ms(10),
        vec![
            obj("A", vec![lv(2, 4.0), lv(5, 7.0)]),
            obj("B", vec![lv(3, 3.0), lv(6, 9.0)]),
            obj("C", vec![lv(4, 6.0)]),
        ],
    )
    .unwrap()
}

#[test]
fn greedy_matches_the_hand_worked_example() {
    let s = greedy(&hand());
    assert_eq!(s.levels, vec![Some(0), Some(1), None]);
    assert_eq!(s.total_cost, Duration::ms(8).0 as u128);
    assert_eq!(s.total_benefit, 13.0);
}

#[test]
fn optimal_finds_the_better_pair() {
    let s = optimal(&hand()).unwrap();
    assert_eq!(s.levels, vec![None, Some(1), Some(0)]);
    assert_eq!(s.total_benefit, 15.0);
    assert_eq!(s.total_cost, Duration::ms(10).0 as u128);
}

#[test]
fn incremental_repairs_then_upgrades() {
    let inst = hand();
    // From nothing: A0 (rate 2), then B1 (1.5, larger gain than C0); C0
    // and A0->A1 no longer fit.
    let s = incremental(&inst, &[None, None, None], None).unwrap();
    assert_eq!(s.levels, vec![Some(0), Some(1), None]);
    // From [A1, B1, C0] (15 ms): repair A1->A0 (loses 1 per ms), then
    // B1->none (1.5 per ms, larger saving than C0->none): 6 ms. Improve:
    // A0->A1 and none->B0 tie at 1 per ms with equal gain; A first: 9 ms.
    let s = incremental(&inst, &[Some(1), Some(1), Some(0)], None).unwrap();
    assert_eq!(s.levels, vec![Some(1), None, Some(0)]);
    assert_eq!(s.total_benefit, 13.0);
    // A per-frame limit of one upgrade stops there.
    let s = incremental(&inst, &[None, None, None], Some(1)).unwrap();
    assert_eq!(s.levels, vec![Some(0), None, None]);
}

#[test]
fn previous_selection_is_checked() {
    let inst = hand();
    assert!(matches!(
        incremental(&inst, &[None], None),
        Err(LodSelectError::PreviousLength { expected: 3, got: 1 })
    ));
    let e = incremental(&inst, &[None, None, Some(1)], None).unwrap_err();
    assert!(e.to_string().contains("\"C\""), "{e}");
}

#[test]
fn zero_cost_and_zero_benefit_levels() {
    let inst = Instance::new(
        Duration::ms(1),
        vec![
            obj("free", vec![lv(0, 1.0), lv(2, 5.0)]),
            obj("useless", vec![lv(0, 0.0), lv(1, 0.0)]),
            obj("small", vec![lv(1, 0.5)]),
        ],
    )
    .unwrap();
    for alg in [Algorithm::Greedy, Algorithm::Incremental, Algorithm::Optimal] {
        let s = inst.select(alg, None).unwrap();
        assert_eq!(s.levels, vec![Some(0), None, Some(0)], "{alg:?}");
        assert_eq!(s.total_benefit, 1.5);
    }
    let sum = SelectionSummary::new(&inst, Algorithm::Greedy, &greedy(&inst), None);
    assert!(sum.notes.iter().any(|n| n.contains("zero benefit")), "{:?}", sum.notes);
    assert!(sum.notes.iter().any(|n| n.contains("cost nothing")), "{:?}", sum.notes);
}

#[test]
fn empty_and_unaffordable() {
    let empty = Instance::new(Duration::ms(1), vec![]).unwrap();
    for alg in [Algorithm::Greedy, Algorithm::Incremental, Algorithm::Optimal] {
        let s = empty.select(alg, None).unwrap();
        assert!(s.levels.is_empty());
        assert_eq!((s.total_cost, s.total_benefit), (0, 0.0));
    }
    let inst = Instance::new(Duration::ms(1), vec![obj("big", vec![lv(2, 1.0), lv(3, 2.0)])]).unwrap();
    assert_eq!(inst.unaffordable(), vec![0]);
    let s = greedy(&inst);
    assert_eq!(s.levels, vec![None]);
    let sum = SelectionSummary::new(&inst, Algorithm::Greedy, &s, None);
    assert_eq!(sum.unaffordable, vec!["big".to_string()]);
    assert!(sum.notes[0].contains("no level of any object fits"), "{:?}", sum.notes);
}

#[test]
fn unordered_levels_are_identifiers() {
    // Level 0 costs more and gives less than level 1 (dominated).
    let inst = Instance::new(
        Duration::ms(10),
        vec![obj("x", vec![lv(5, 1.0), lv(2, 3.0), lv(9, 4.0)])],
    )
    .unwrap();
    assert_eq!(greedy(&inst).levels, vec![Some(1)]);
    assert_eq!(optimal(&inst).unwrap().levels, vec![Some(2)]);
}

#[test]
fn bad_benefits_name_object_and_level() {
    for (b, what) in [(-1.0, "negative"), (f64::NAN, "NaN"), (f64::INFINITY, "infinite")] {
        let e = Instance::new(
            Duration::ms(1),
            vec![obj("ok", vec![lv(1, 1.0)]), obj("bad", vec![lv(1, 1.0), lv(2, b)])],
        )
        .unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("\"bad\"") && m.contains("objects[1]") && m.contains("level 1") && m.contains(what),
            "{m}"
        );
    }
    let e = Instance::new(Duration::ms(1), vec![obj("none", vec![])]).unwrap_err();
    assert!(e.to_string().contains("no levels"), "{e}");
}

#[test]
fn optimal_refuses_large_instances() {
    let objects = (0..31).map(|i| obj(&format!("o{i}"), vec![lv(1, 1.0)])).collect();
    let inst = Instance::new(Duration::ms(10), objects).unwrap();
    let e = optimal(&inst).unwrap_err();
    assert!(
        matches!(e, LodSelectError::TooLargeForOptimal { objects: 31, limit: 30 }),
        "{e}"
    );
}

#[test]
fn instance_files() {
    let inst = parse_instance(
        r#"
budget = "10ms"
[[objects]]
name = "tree-1"
levels = [{ cost = "0.4ms", benefit = 1.0 }, { cost = "1.1ms", benefit = 2.2 }]
[[objects]]
name = "free"
levels = [{ cost = 0, benefit = 1 }]
"#,
    )
    .unwrap();
    assert_eq!(inst.objects()[0].levels[1].cost, Duration(1_100_000_000));
    assert_eq!(inst.objects()[1].levels[0], lv(0, 1.0));
    assert!(parse_instance("budget = \"1ms\"").unwrap().objects().is_empty());
    let bad = |text: &str, want: &[&str]| {
        let m = parse_instance(text).unwrap_err().to_string();
        for w in want {
            assert!(m.contains(w), "{w:?} not in {m:?}");
        }
    };
    let one = |levels: &str| format!("budget = \"1ms\"\n[[objects]]\nname = \"t\"\nlevels = [{levels}]\n");
    bad(
        &one(r#"{ cost = "-1ms", benefit = 1.0 }"#),
        &["\"t\"", "level 0", "negative"],
    );
    bad(&one(r#"{ cost = "1", benefit = 1.0 }"#), &["\"t\"", "level 0", "unit"]);
    bad(&one(r#"{ cost = 2, benefit = 1.0 }"#), &["level 0", "needs a unit"]);
    bad(
        &one(r#"{ cost = "1ms", benefit = -0.5 }"#),
        &["\"t\"", "level 0", "negative"],
    );
    bad(&one(r#"{ cost = "1ms", benefit = nan }"#), &["NaN"]);
    bad(&one(r#"{ cost = "1ms", benefit = 1.0, colour = 1 }"#), &["colour"]);
    bad(&one(""), &["no levels"]);
    bad("[[objects]]\nname = \"t\"\nlevels = []\n", &["budget"]);
    bad("budget = \"1 fortnight\"\n", &["budget", "unit"]);
    bad(
        "budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = [{ cost = \"1ms\", benefit = 1.0 }]\n[[objects]]\nname = \"a\"\nlevels = [{ cost = \"1ms\", benefit = 1.0 }]\n",
        &["objects[0]", "objects[1]", "\"a\"", "unique"],
    );
}

#[test]
fn json_instances_read_like_toml() {
    let j = parse_instance_json(
        r#"{"budget": "10ms", "objects": [{"name": "t", "levels": [{"cost": "0.4ms", "benefit": 1}, {"cost": 0, "benefit": 0.5}]}]}"#,
    )
    .unwrap();
    let t = parse_instance(
        "budget = \"10ms\"\n[[objects]]\nname = \"t\"\nlevels = [{ cost = \"0.4ms\", benefit = 1.0 }, { cost = 0, benefit = 0.5 }]\n",
    )
    .unwrap();
    assert_eq!(j, t);
    let e = parse_instance_json(
        r#"{"budget": "1ms", "objects": [{"name": "t", "levels": [{"cost": "-1ms", "benefit": 1}]}]}"#,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("\"t\"") && e.to_string().contains("negative"),
        "{e}"
    );
}

#[test]
fn instance_errors_name_the_line_and_key() {
    let text = "budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = [{ cost = \"1ms\", benefit = 1.0 }]\n[[objects]]\nname = \"b\"\nlevels = [\n  { cost = \"1ms\", benefit = 1.0 },\n  { cost = \"2ms\", benefit = nan },\n]\n";
    let e = parse_instance(text).unwrap_err().to_string();
    assert!(
        e.starts_with("instance:9: key `objects.1.levels.1.benefit`: object \"b\" (objects[1]) level 1: benefit NaN"),
        "{e}"
    );
    let e = parse_instance(&text.replace("nan", "-inf")).unwrap_err().to_string();
    assert!(
        e.contains("key `objects.1.levels.1.benefit`") && e.contains("infinite"),
        "{e}"
    );
    let e = parse_instance(&text.replace("\"2ms\"", "\"-2ms\"").replace("nan", "1"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("instance:9: key `objects.1.levels.1.cost`: "), "{e}");
    let e = parse_instance("budget = \"1e30s\"\n").unwrap_err().to_string();
    assert!(e.starts_with("instance:1: key `budget`: "), "{e}");
    let e = parse_instance("budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = []\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("instance:4: key `objects.0.levels`: ") && e.contains("no levels"),
        "{e}"
    );
    let e = parse_instance("budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = [{ cost = 0, benefit = 1 }]\n[[objects]]\nname = \"a\"\nlevels = [{ cost = 0, benefit = 1 }]\n")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("instance:6: key `objects.1.name`: "), "{e}");
    // Serde's errors through the model files' machinery: key and line.
    let e = parse_instance(
        "budget = \"1ms\"\n[[objects]]\nname = \"a\"\nlevels = [{ cost = 0, benefit = 1, colour = 2 }]\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("instance:4") && e.contains("colour"), "{e}");
    let e = parse_instance("budget = \"1ms\"\n[[objects]]\nname = 3\nlevels = []\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("instance:3") && e.contains("objects.0.name"), "{e}");
    // JSON: the key (no line).
    let e = parse_instance_json(
        r#"{"budget": "1ms", "objects": [{"name": "t", "levels": [{"cost": "1ms", "benefit": -1}]}]}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("instance: key `objects.0.levels.0.benefit`: "), "{e}");
}

#[test]
fn benefits_must_add_up_to_a_finite_sum() {
    let big = f64::MAX / 1.5;
    let objects = vec![obj("a", vec![lv(1, big)]), obj("b", vec![lv(1, 1.0), lv(2, big)])];
    let e = Instance::new(Duration::ms(10), objects).unwrap_err();
    assert!(matches!(&e, LodSelectError::Benefit { index: 1, level: 1, .. }), "{e}");
    assert!(e.to_string().contains("infinite"), "{e}");
    // Large but summable benefits stay valid and give finite totals.
    let objects = vec![obj("a", vec![lv(1, big / 2.0)]), obj("b", vec![lv(1, big / 2.0)])];
    let inst = Instance::new(Duration::ms(10), objects).unwrap();
    for s in [greedy(&inst), optimal(&inst).unwrap()] {
        assert!(s.total_benefit.is_finite(), "{s:?}");
    }
}
