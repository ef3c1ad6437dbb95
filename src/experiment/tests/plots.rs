//! The plots an experiment file asks for: point and series labels, a line
//! plot's `where`, histogram marks and ranges, categorical x axes; run
//! against the fake simulator of `tests.rs`.

use super::*;

#[test]
fn plots_name_points_by_the_sweeps_labels() {
    let exp = parse(
        r#"
name = "labels"
[[sweep]]
key = "display.buffers"
values = [2, 3]
labels = ["double buffering", "triple buffering"]
[[sweep]]
key = "workload.gpu"
values = ["10ms", "20ms"]
"#,
    );
    let pts = expand_points(&exp);
    // The CSV's and the report's label keeps the values ...
    assert_eq!(pts[3].label(), "display.buffers=3, workload.gpu=20ms");
    // ... plots show the labels where the file gave them, values elsewhere.
    assert_eq!(pts[3].plot_label(&exp.sweeps), "triple buffering, workload.gpu=20ms");
    assert_eq!(pts[0].plot_assignment(&exp.sweeps, 0), "double buffering");
    assert_eq!(
        expand_points(&parse("name = \"x\"\n"))[0].plot_label(&[]),
        "(single point)"
    );
}

#[test]
fn line_plot_where_selects_points() {
    let text = format!(
        "{BASIC}\n[[plot]]\nfile = \"two\"\nkind = \"line\"\nx = \"workload.gpu\"\n\
         y = \"metrics.display_interval_ms.mean\"\nwhere = {{ \"display.buffers\" = 3 }}\n"
    );
    let exp = parse(&text);
    let PlotKind::Line { filter, .. } = &exp.plots[1].kind else {
        panic!("not a line plot")
    };
    assert_eq!(filter.len(), 1);
    let dir = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    let svg = read(dir.path(), "two.svg");
    // One series (buffers = 3), named after the metric, not the filtered key.
    assert!(!svg.contains("display.buffers=2"), "{svg}");
    assert!(read(dir.path(), "interval.svg").contains("display.buffers=2"));
    assert!(dir.path().join("two.png").exists());

    let bad = format!(
        "{BASIC}\n[[plot]]\nfile = \"bad\"\nkind = \"line\"\nx = \"workload.gpu\"\n\
         y = \"metrics.display_interval_ms.mean\"\nwhere = {{ \"workload.gpu\" = \"10ms\" }}\n"
    );
    assert!(parse_err(&bad).contains("must not fix the x axis key"));
    let bad = format!(
        "{BASIC}\n[[plot]]\nfile = \"bad\"\nkind = \"line\"\nx = \"workload.gpu\"\n\
         y = \"metrics.display_interval_ms.mean\"\nwhere = {{ \"display.buffers\" = 4 }}\n"
    );
    assert!(parse_err(&bad).contains("not one of the swept values"));
}

#[test]
fn histogram_marks_are_parsed_and_validated() {
    let plot = |kind: &str, extra: &str| {
        format!(
            "name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"{kind}\"\ncolumn = \"FrameTime\"\nx = \"a\"\ny = \"b\"\n{extra}"
        )
    };
    let exp = parse(&plot(
        "histogram",
        "marks = [{ at = 337, label = \"paper: best\" }, { at = 390.5, label = \"worst\" }]\n",
    ));
    let PlotKind::Histogram { marks, .. } = &exp.plots[0].kind else {
        panic!("a histogram")
    };
    assert_eq!(
        marks.iter().map(|m| (m.at, m.label.as_str())).collect::<Vec<_>>(),
        [(337.0, "paper: best"), (390.5, "worst")]
    );
    for (kind, bad, want) in [
        ("histogram", "marks = [{ at = nan, label = \"x\" }]\n", "marks.0.at"),
        ("histogram", "marks = [{ at = 1, label = \"\" }]\n", "marks.0.label"),
        ("histogram", "marks = [{ at = 1 }]\n", "label"),
        (
            "histogram",
            "marks = [{ at = 1, label = \"x\", colour = 1 }]\n",
            "colour",
        ),
    ] {
        let e = parse_err(&plot(kind, bad));
        assert!(e.contains(want), "{bad}: {e}");
    }
    let e = parse_err(
        "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[plot]]\nfile = \"l\"\nkind = \"line\"\nx = \"a\"\ny = \"metrics.frame_time_ms.mean\"\nmarks = [{ at = 1, label = \"x\" }]\n",
    );
    assert!(e.contains("only histogram plots take `marks`"), "{e}");
}

#[test]
fn histogram_marks_above_the_minimum_are_parsed_apart_and_validated() {
    let hist = |extra: &str| {
        format!("name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\n{extra}")
    };
    let exp = parse(&hist(
        "marks = [{ at = 11.92, label = \"axis\" }, { above_min = 1.52, label = \"paper c\" }]\n",
    ));
    let PlotKind::Histogram {
        marks, marks_above_min, ..
    } = &exp.plots[0].kind
    else {
        panic!("a histogram")
    };
    assert_eq!(marks.iter().map(|m| m.at).collect::<Vec<_>>(), [11.92]);
    assert_eq!(
        marks_above_min
            .iter()
            .map(|m| (m.at, m.label.as_str()))
            .collect::<Vec<_>>(),
        [(1.52, "paper c")]
    );
    for (bad, want) in [
        (
            "marks = [{ above_min = -1, label = \"x\" }]\n",
            "marks.0.above_min`: must be a finite number, 0 or more",
        ),
        ("marks = [{ above_min = nan, label = \"x\" }]\n", "marks.0.above_min"),
        ("marks = [{ at = 1, above_min = 1, label = \"x\" }]\n", "not both"),
        ("marks = [{ label = \"x\" }]\n", "needs `at` (a value) or `above_min`"),
    ] {
        let e = parse_err(&hist(bad));
        assert!(e.contains(want), "{bad}: {e}");
    }
}

#[test]
fn marks_above_the_minimum_sit_at_the_lowest_value_plotted() {
    use crate::experiment::figures::histogram_marks;
    use crate::plot::Mark;
    let mark = |at: f64, label: &str| Mark {
        at,
        label: label.into(),
    };
    let values = vec![
        ("a".to_string(), vec![12.5, 12.1, f64::NAN]),
        ("b".to_string(), vec![f64::NEG_INFINITY, 12.3, 14.0]),
    ];
    let got = histogram_marks(&[mark(11.92, "axis")], &[mark(1.52, "paper c")], &values);
    assert_eq!(got.len(), 2);
    assert_eq!((got[0].at, got[0].label.as_str()), (11.92, "axis"));
    assert!((got[1].at - (12.1 + 1.52)).abs() < 1e-12 && got[1].label == "paper c");
    // Nothing plotted: no minimum to measure from.
    let none = histogram_marks(&[], &[mark(1.52, "paper c")], &[("a".into(), vec![f64::NAN])]);
    assert!(none.is_empty());
}

#[test]
fn histogram_range_is_parsed_and_validated() {
    let hist = |extra: &str| {
        format!("name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\n{extra}")
    };
    // Integers are fine; no range means the bins span the data.
    let exp = parse(&hist("range = [11, 14.5]\n"));
    assert!(matches!(
        exp.plots[0].kind,
        PlotKind::Histogram {
            range: Some((11.0, 14.5)),
            ..
        }
    ));
    let exp = parse(&hist(""));
    assert!(matches!(exp.plots[0].kind, PlotKind::Histogram { range: None, .. }));
    for (bad, want) in [
        ("range = [3, 3]\n", "needs lo < hi, got [3, 3]"),
        ("range = [5.0, 1.0]\n", "needs lo < hi"),
        ("range = [1.0]\n", "must be [lo, hi] (two numbers), got 1 value(s)"),
        ("range = [1, 2, 3]\n", "got 3 value(s)"),
        ("range = [nan, 2.0]\n", "bounds must be finite"),
        ("range = [0.0, inf]\n", "bounds must be finite"),
    ] {
        let e = parse_err(&hist(bad));
        assert!(
            e.contains("experiments/bad.toml") && e.contains("plot[0] (h).range") && e.contains(want),
            "{bad}: {e}"
        );
    }
    let e = parse_err(&hist("range = [\"a\", \"b\"]\n"));
    assert!(e.contains("experiments/bad.toml") && e.contains("range"), "{e}");
    let e = parse_err(
        "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[plot]]\nfile = \"p\"\nkind = \"line\"\nx = \"a\"\ny = \"m\"\nrange = [0, 1]\n",
    );
    assert!(
        e.contains("plot[0] (p).range") && e.contains("only histogram plots take `range`"),
        "{e}"
    );
}

#[test]
fn histogram_range_counts_values_outside_in_the_report() {
    let text = FIDELITY.replace("bins = 20\n", "bins = 20\nrange = [12, 25]\n");
    let exp = parse(&text);
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    // Frames are gpu + (i % 10) for 100 frames and 2 seeds: at 10ms, 10 and 11
    // fall below 12 (40 values); at 20ms, 26..29 lie above 25 (80 values).
    let captions: Vec<&str> = res.plot_captions.iter().map(|c| c.1.as_str()).collect();
    assert_eq!(captions.len(), 2, "{captions:?}");
    assert!(res.plot_captions.iter().all(|c| c.0 == "frames"));
    assert!(
        captions[0].starts_with("x range [12, 25]: 40 value(s) below and 0 above of 200 not shown (")
            && captions[0].contains("10ms"),
        "{captions:?}"
    );
    assert!(captions[1].contains("0 value(s) below and 80 above") && captions[1].contains("20ms"));
    let report = read(dir.path(), "report.md");
    assert!(report.contains(&format!("Note: {}.", captions[0])), "{report}");
    // Without a range there are no captions.
    let res = run_experiment(&parse(FIDELITY), &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert!(res.plot_captions.is_empty());
}

#[test]
fn array_sweep_values_label_the_x_axis() {
    let exp = parse(
        r#"
name = "arrays"
[[sweep]]
key = "resolution"
values = [[1024, 768], [1280, 1024]]
[[metric]]
path = "metrics.display_interval_ms.mean"
[[plot]]
file = "res"
kind = "line"
x = "resolution"
y = "metrics.display_interval_ms.mean"
"#,
    );
    assert!(exp.sweeps[0].categorical);
    assert_eq!(exp.sweeps[0].coords, vec![0.0, 1.0]);
    let dir = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    let svg = read(dir.path(), "res.svg");
    assert!(svg.contains("[1024, 768]") && svg.contains("[1280, 1024]"), "{svg}");
}

#[test]
fn a_sweep_of_tables_is_selected_by_its_whole_table() {
    let head = r#"
name = "tables"
[[sweep]]
key = "workload.groups.0.changes"
values = [{ texture = 4, matrix = 1 }, { texture = 2, matrix = 4 }]
[[sweep]]
key = "display.buffers"
values = [2, 3]
[[metric]]
path = "metrics.display_interval_ms.mean"
"#;
    let exp = parse(&format!(
        "{head}[[check]]\npath = \"metrics.display_interval_ms.mean\"\n\
         where = {{ \"workload.groups.0.changes\" = {{ matrix = 4, texture = 2 }}, \"display.buffers\" = 3 }}\n\
         at_least = 0\ntolerance = 0\n"
    ));
    let filter = &exp.checks[0].filter;
    assert_eq!(filter.len(), 2, "{filter:?}");
    assert!(
        filter
            .iter()
            .any(|(k, v)| k == "workload.groups.0.changes" && v.is_table()),
        "{filter:?}"
    );
    assert_eq!(expand_points(&exp).iter().filter(|p| p.matches(filter)).count(), 1);
    // A table that is not one of the values, and a key below the sweep's.
    let e = parse_err(&format!(
        "{head}[[check]]\npath = \"x\"\nwhere = {{ \"workload.groups.0.changes\" = {{ texture = 3 }} }}\nexpect = 1\ntolerance = 0\n"
    ));
    assert!(e.contains("is not one of the swept values"), "{e}");
    let e = parse_err(&format!(
        "{head}[[check]]\npath = \"x\"\nwhere = {{ \"workload.groups.0.changes.texture\" = 4 }}\nexpect = 1\ntolerance = 0\n"
    ));
    assert!(
        e.contains("`workload.groups.0.changes.texture` is not a sweep key"),
        "{e}"
    );
}

/// An experiment with one line plot of `m` over sweep `a`, `extra` added
/// to the plot.
fn line(extra: &str) -> String {
    format!(
        "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[plot]]\nfile = \"p\"\nkind = \"line\"\nx = \"a\"\ny = \"m\"\n{extra}"
    )
}

#[test]
fn y_bounds_belong_to_line_plots_and_must_be_an_ordered_pair() {
    let exp = parse(&line("y_bounds = [0, 1]\n"));
    assert!(matches!(
        exp.plots[0].kind,
        PlotKind::Line {
            y_bounds: Some((0.0, 1.0)),
            ..
        }
    ));
    for (bad, want) in [
        ("y_bounds = [1, 0]\n", "the first below the second"),
        ("y_bounds = [0]\n", "needs [lowest, highest]"),
        ("y_bounds = [0, inf]\n", "two finite numbers"),
        ("y_bounds = [0, 1]\nlog_y = true\n", "above 0 on a log axis"),
    ] {
        let e = parse_err(&line(bad));
        assert!(e.contains("plot[0] (p).y_bounds") && e.contains(want), "{bad}: {e}");
    }
    let e = parse_err(
        "name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\ny_bounds = [0, 1]\n",
    );
    assert!(e.contains("only line plots take `y_bounds`"), "{e}");
}

#[test]
fn a_y_axis_is_checked_as_bounds_are_and_drawn_whole() {
    let exp = parse(&line("y_axis = [0, 300]\n"));
    assert!(matches!(
        exp.plots[0].kind,
        PlotKind::Line {
            y_axis: Some((0.0, 300.0)),
            y_bounds: None,
            ..
        }
    ));
    let e = parse_err(&line("y_axis = [5, 5]\n"));
    assert!(
        e.contains("plot[0] (p).y_axis") && e.contains("the first below the second"),
        "{e}"
    );
    let e = parse_err(
        "name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\ny_axis = [0, 1]\n",
    );
    assert!(e.contains("only line plots take `y_axis`"), "{e}");
    // Drawn: the axis runs from 0 though the data lie between 264 and 280.
    let plot = |y_axis| crate::plot::LinePlot {
        title: "t".into(),
        series: vec![crate::plot::Series {
            name: "s".into(),
            points: vec![(1.0, 264.0), (2.0, 280.0)],
            ..Default::default()
        }],
        y_axis,
        ..Default::default()
    };
    let svg = |y_axis| crate::plot::line_plot_svg(&plot(y_axis)).unwrap();
    let (free, whole) = (svg(None), svg(Some((0.0, 300.0))));
    let tick = |svg: &str, label: &str| svg.contains(&format!(">\n{label}\n</text>"));
    assert!(tick(&whole, "0") && tick(&whole, "300"), "the whole axis is labelled");
    assert!(!tick(&free, "0"), "a free axis hugs the data");
}

#[test]
fn paper_values_are_drawn_as_crosses_at_their_points() {
    let text = format!(
        "{BASIC}\n[[plot]]\nfile = \"ref\"\nkind = \"line\"\nx = \"workload.gpu\"\n\
         y = \"metrics.display_interval_ms.mean\"\n\
         paper = [{{ where = {{ \"workload.gpu\" = \"12ms\", \"display.buffers\" = 2 }}, value = 16.7 }},\n\
         {{ where = {{ \"workload.gpu\" = \"16ms\" }}, value = 33.3 }}]\n"
    );
    let exp = parse(&text);
    let PlotKind::Line { paper, .. } = &exp.plots[1].kind else {
        panic!("not a line plot")
    };
    assert_eq!(paper.len(), 2);
    assert_eq!(paper[0].value, 16.7);
    let dir = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    let with = read(dir.path(), "ref.svg");
    assert!(with.contains("paper"), "no legend entry for the paper's values");
    // The same plot without them has no such entry and fewer strokes.
    let plain = read(dir.path(), "interval.svg");
    assert!(!plain.contains("paper"));
    let line = |extra: &str| {
        format!(
            "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[sweep]]\nkey = \"b\"\nvalues = [3, 4]\n\
             [[plot]]\nfile = \"p\"\nkind = \"line\"\nx = \"a\"\ny = \"m\"\n{extra}"
        )
    };
    for (bad, want) in [
        (
            "paper = [{ where = { b = 3 }, value = 1 }]\n",
            "paper.0.where`: must fix the x axis key `a`",
        ),
        (
            "paper = [{ where = { a = 5 }, value = 1 }]\n",
            "`a` = 5 is not one of the swept values",
        ),
        (
            "paper = [{ where = { a = 1 }, value = nan }]\n",
            "paper.0.value`: must be a finite number",
        ),
        ("paper = [{ where = { c = 1 }, value = 1 }]\n", "`c` is not a sweep key"),
        ("paper = [{ where = { a = 1 } }]\n", "needs `value`"),
    ] {
        let e = parse_err(&line(bad));
        assert!(e.contains(want), "{bad}: {e}");
    }
    let e =
        parse_err("name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\npaper = []\n");
    assert!(e.contains("only line and bar plots take `paper`"), "{e}");
    // What the values are called.
    let named = parse(&line(
        "paper = [{ where = { a = 1 }, value = 1 }]\npaper_label = \"measured\"\n",
    ));
    assert_eq!(named.plots[0].paper_label, "measured");
    assert_eq!(parse(&line("")).plots[0].paper_label, "paper");
    for (bad, want) in [
        ("paper_label = \"measured\"\n", "give `paper` or `paper_levels` too"),
        ("paper = []\npaper_label = \" \"\n", "1 to 60 characters"),
    ] {
        let e = parse_err(&line(bad));
        assert!(e.contains("paper_label") && e.contains(want), "{bad}: {e}");
    }
}

#[test]
fn bar_plots_group_by_path_and_put_the_paper_beside() {
    let text = format!(
        "{BASIC}\n[[plot]]\nfile = \"bars\"\nkind = \"bars\"\n\
         y = [\"metrics.display_interval_ms.mean\", \"metrics.fixed_kind\"]\nlog_y = true\n\
         where = {{ \"workload.gpu\" = \"10ms\" }}\n\
         paper = [{{ where = {{ \"workload.gpu\" = \"10ms\", \"display.buffers\" = 2 }}, values = [16.7, 1.0] }}]\n"
    );
    let exp = parse(&text);
    let PlotKind::Bars {
        y,
        log_y,
        filter,
        paper,
    } = &exp.plots[1].kind
    else {
        panic!("not a bar plot")
    };
    assert_eq!((y.len(), *log_y, filter.len(), paper.len()), (2, true, 1, 1));
    let dir = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    // report.md says the paper's values beside the simulated ones, with the
    // ratio, and how the points agree with them: the fake's interval at
    // 10 ms is one refresh, 16.667 ms, against 16.7; its kind is 1 against 1.
    let report = read(dir.path(), "report.md");
    for row in [
        "## Beside the paper",
        "| workload.gpu=10ms, display.buffers=2 | display interval (ms) | 16.67 | 16.70 | 0.998x |",
        "| workload.gpu=10ms, display.buffers=2 | metrics.fixed_kind | 1.000 | 1.000 | 1.000x |",
        "| all points | 2 | 2 | 0.999x |",
    ] {
        assert!(report.contains(row), "report.md should have {row:?}:\n{report}");
    }
    let svg = read(dir.path(), "bars.svg");
    // Two kept points, simulated, and the paper's entry named after its point.
    assert_eq!(svg.matches("(simulated)").count(), 2, "{svg}");
    // Named without the key the filter fixes.
    assert!(
        svg.contains("display.buffers=2 (paper)") && !svg.contains("workload.gpu=10ms"),
        "{svg}"
    );
    assert!(
        svg.contains("display interval (ms)"),
        "categories from the metric labels"
    );
    let bars = |extra: &str| {
        format!(
            "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[plot]]\nfile = \"p\"\nkind = \"bars\"\n{extra}"
        )
    };
    for (bad, want) in [
        ("", "needs one or more metric paths"),
        ("y = \"m\"\nx = \"a\"\n", "has no x axis"),
        (
            "y = [\"m\", \"n\"]\npaper = [{ where = { a = 1 }, values = [1] }]\n",
            "needs 2 finite numbers",
        ),
        (
            "y = \"m\"\npaper = [{ where = { a = 1 }, value = 1 }]\n",
            "needs `values`",
        ),
        (
            "y = \"m\"\npaper = [{ where = { a = 3 }, values = [1] }]\n",
            "`a` = 3 is not one of the swept values",
        ),
    ] {
        let e = parse_err(&bars(bad));
        assert!(e.contains(want), "{bad}: {e}");
    }
}

#[test]
fn derived_values_are_named_on_plots_by_their_label() {
    let text = "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[metric]]\npath = \"m\"\n\
                [[derived]]\nname = \"r\"\nkind = \"ratio\"\npath = \"m\"\nreference = { a = 1 }\nlabel = \"m against a = 1\"\n\
                [[derived]]\nname = \"plain\"\nkind = \"ratio\"\npath = \"m\"\nreference = { a = 1 }\n";
    let exp = parse(text);
    assert_eq!(exp.label_of("r"), "m against a = 1");
    assert_eq!(exp.label_of("plain"), "plain");
    let e = parse_err(&text.replace("label = \"m against a = 1\"", "label = \" \""));
    assert!(
        e.contains("derived[0] (r).label") && e.contains("must not be empty"),
        "{e}"
    );
}

#[test]
fn a_line_plots_paper_levels_are_one_per_path_drawn_dashed_and_named() {
    // The display interval's published level, 16.7 ms, drawn across the
    // plot in its series' colour and named in the legend.
    let text = format!(
        "{BASIC}\n[[plot]]\nfile = \"levels\"\nkind = \"line\"\nx = \"workload.gpu\"\n\
         y = [\"metrics.display_interval_ms.mean\"]\nwhere = {{ \"display.buffers\" = 2 }}\n\
         paper_levels = [16.7]\npaper_label = \"measured\"\n"
    );
    let exp = parse(&text);
    let PlotKind::Line { levels, .. } = &exp.plots[1].kind else {
        panic!("not a line plot")
    };
    assert_eq!(levels, &vec![16.7]);
    let dir = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    let svg = read(dir.path(), "levels.svg");
    assert!(svg.contains("(dashed: measured 16.7)"), "{svg}");
    // The same plot without the level: no dashed line, no such name.
    let plain = parse(&text.replace("paper_levels = [16.7]\npaper_label = \"measured\"\n", ""));
    let dir2 = tempfile::tempdir().unwrap();
    run_experiment(&plain, &base_model(), &Fake::default(), dir2.path(), false).unwrap();
    let without = read(dir2.path(), "levels.svg");
    assert!(!without.contains("dashed"));
    // plotters draws a dashed line as short segments: many more paths.
    let segments =
        |svg: &str| svg.matches("<polyline").count() + svg.matches("<line").count() + svg.matches("<path").count();
    assert!(
        segments(&svg) > segments(&without) + 10,
        "the level is drawn dashed: {} against {} segments",
        segments(&svg),
        segments(&without)
    );
    // One finite number per `y` path (above 0 on a log axis), on line plots only.
    let line = |extra: &str| {
        format!(
            "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n[[plot]]\nfile = \"p\"\nkind = \"line\"\nx = \"a\"\n\
             y = [\"m\", \"n\"]\n{extra}"
        )
    };
    for (bad, want) in [
        (
            "paper_levels = [1.0]\n",
            "needs 2 finite numbers, one per `y` path; got [1.0]",
        ),
        ("paper_levels = []\n", "needs 2 finite numbers"),
        ("paper_levels = [1.0, nan]\n", "needs 2 finite numbers"),
        (
            "log_y = true\npaper_levels = [1.0, 0.0]\n",
            "each above 0 on a log axis",
        ),
    ] {
        let e = parse_err(&line(bad));
        assert!(e.contains("plot[0] (p).paper_levels") && e.contains(want), "{bad}: {e}");
    }
    assert_eq!(parse(&line("paper_levels = [1.0, -2.0]\n")).plots.len(), 1);
    let e = parse_err(
        "name = \"x\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"FrameTime\"\npaper_levels = [1.0]\n",
    );
    assert!(e.contains("only line plots take `paper_levels`"), "{e}");
}
