//! Unit tests of `passes.rs`.

use super::*;

fn row(mesh: &str, vs: u32, t: f64) -> PassRow {
    PassRow {
        mesh: mesh.into(),
        size: (384, 384).into(),
        vs_loops: vs,
        fs_loops: 0,
        geometry_only: false,
        vs_invocations: 15570,
        fs_invocations: 147456,
        pass_time_ns: t,
        draws: 1,
    }
}

fn shared(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("docs/measurements/nvidia-h200")
        .join(name)
}

#[test]
fn the_serialized_header_is_the_pass_header() {
    assert_eq!(COLUMNS.join(","), PASS_HEADER);
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row("grid:96x96:optimized", 0, 55200.0)).unwrap();
    let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
    assert_eq!(
        text,
        format!("{PASS_HEADER}\ngrid:96x96:optimized,384x384,0,0,false,15570,147456,55200.0,1\n")
    );
}

#[test]
fn the_shared_h200_files_read_back() {
    let grid = read_passes(&shared("load-grid.csv")).unwrap();
    assert_eq!(grid.len(), 19);
    assert_eq!(grid[3].fs_loops, 7681);
    assert_eq!(grid[3].pass_time_ns, 22844640.0);
    assert!(grid[4].geometry_only && grid[4].fs_invocations == 0);
    let sweep = read_passes(&shared("load-sweep.csv")).unwrap();
    assert_eq!(sweep.len(), 76);
    let last = sweep.last().unwrap();
    assert_eq!(last.mesh, "random:30000:5000:7");
    assert_eq!(
        last.size,
        TargetSize {
            width: 2048,
            height: 2048
        }
    );
    assert!(sweep.iter().chain(&grid).all(|r| r.draws == 1));
    // Every row written back reads the same; appended to a file of the
    // same (older) header, it is written in that format.
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("copy.csv");
    std::fs::write(&copy, format!("{LEGACY_PASS_HEADER}\n")).unwrap();
    append_passes(&copy, &sweep).unwrap();
    assert_eq!(read_passes(&copy).unwrap(), sweep);
    // Byte for byte, but for the shared file's CRLF line endings.
    assert_eq!(
        std::fs::read_to_string(&copy).unwrap(),
        std::fs::read_to_string(shared("load-sweep.csv"))
            .unwrap()
            .replace("\r\n", "\n")
    );
}

#[test]
fn malformed_rows_name_file_line_and_column() {
    let bad = |text: &str| {
        read_passes_from(text.as_bytes(), Path::new("x.csv"))
            .unwrap_err()
            .to_string()
    };
    let e = bad(&format!(
        "{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,false,81,4096,1.0\ngrid:8x8,64by64,0,0,false,81,4096,1.0\n"
    ));
    assert!(e.starts_with("x.csv: line 3, column 2 (size): "), "{e}");
    assert!(e.contains("expected WxH"), "{e}");
    let e = bad(&format!(
        "{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,-1,0,false,81,4096,1.0\n"
    ));
    assert!(e.starts_with("x.csv: line 2, column 3 (vs_loops): "), "{e}");
    let e = bad(&format!("{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,yes,81,4096,1.0\n"));
    assert!(e.starts_with("x.csv: line 2, column 5 (geometry_only): "), "{e}");
    let e = bad(&format!(
        "{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,false,81,4096,fast\n"
    ));
    assert!(e.starts_with("x.csv: line 2, column 8 (pass_time_ns): "), "{e}");
    let e = bad(&format!("{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,false,81\n"));
    assert!(
        e.starts_with("x.csv: line 2, column 0 (row): 6 fields, expected 8"),
        "{e}"
    );
    let e = bad("mesh,size,time\ngrid:8x8,64x64,1.0\n");
    assert!(e.contains("x.csv: line 1 is the header \"mesh,size,time\""), "{e}");
    let missing = read_passes(Path::new("/nonexistent/passes.csv"))
        .unwrap_err()
        .to_string();
    assert!(missing.starts_with("reading /nonexistent/passes.csv: "), "{missing}");
}

#[test]
fn values_no_measurement_gives_name_file_line_and_column() {
    let bad = |cells: &str| {
        read_passes_from(
            format!("{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,false,81,4096,1.0\n{cells}\n").as_bytes(),
            Path::new("x.csv"),
        )
        .unwrap_err()
        .to_string()
    };
    for (cells, want) in [
        ("grid:8x8,64x64,0,0,false,81,4096,nan", "column 8 (pass_time_ns): NaN"),
        ("grid:8x8,64x64,0,0,false,81,4096,NaN", "column 8 (pass_time_ns): NaN"),
        ("grid:8x8,64x64,0,0,false,81,4096,inf", "column 8 (pass_time_ns): inf"),
        ("grid:8x8,64x64,0,0,false,81,4096,-inf", "column 8 (pass_time_ns): -inf"),
        ("grid:8x8,64x64,0,0,false,81,4096,-5", "column 8 (pass_time_ns): -5"),
        ("grid:8x8,64x64,0,0,false,81,4096,0", "column 8 (pass_time_ns): 0"),
        ("grid:8x8,64x64,0,0,false,81,4096,-0.0", "column 8 (pass_time_ns)"),
        ("grid:8x8,64x64,0,0,false,81,4096,1e400", "column 8 (pass_time_ns): inf"),
        ("grid:8x8,64x64,0,0,false,81,4096,1e13", "one hour"),
        (
            "grid:axb,64x64,0,0,false,81,4096,1.0",
            "column 1 (mesh): \"grid:axb\" is no mesh spec",
        ),
        ("probe,64x64,0,0,false,81,4096,1.0", "column 1 (mesh)"),
        (",64x64,0,0,false,81,4096,1.0", "column 1 (mesh): is empty"),
        ("grid:8x8,0x64,0,0,false,81,4096,1.0", "column 2 (size): 0x64"),
        ("grid:8x8,64x99999,0,0,false,81,4096,1.0", "column 2 (size): 64x99999"),
        ("grid:8x8,64x64,0,0,false,0,4096,1.0", "column 6 (vs_invocations): 0"),
        ("grid:8x8,64x64,0,0,false,-1,4096,1.0", "column 6 (vs_invocations)"),
        ("grid:8x8,64x64,0,0,false,81,-1,1.0", "column 7 (fs_invocations)"),
        ("grid:8x8,64x64,0,4294967296,false,81,1,1.0", "column 4 (fs_loops)"),
    ] {
        let e = bad(cells);
        assert!(e.starts_with("x.csv: line 3, column "), "{cells}: {e}");
        assert!(e.contains(want), "{cells}: {want:?} not in {e}");
    }
    // The largest values a measurement can give still read.
    let ok = read_passes_from(
        format!("{LEGACY_PASS_HEADER}\ngrid:8x8,16384x16384,4294967295,4294967295,true,1,0,3.6e12\n").as_bytes(),
        Path::new("x.csv"),
    )
    .unwrap();
    assert_eq!(ok[0].pass_time_ns, 3.6e12);
}

#[test]
fn rows_carry_their_lines() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.csv");
    std::fs::write(
        &path,
        format!(
            "{LEGACY_PASS_HEADER}\ngrid:8x8,64x64,0,0,false,81,4096,1.0\n\"grid:8x8\",64x64,0,0,false,81,4096,2.0\n"
        ),
    )
    .unwrap();
    let rows = read_passes_with_lines(&path).unwrap();
    assert_eq!(rows.iter().map(|(_, l)| *l).collect::<Vec<_>>(), [2, 3]);
    // CRLF line endings (the shared H200 files): the file's own line
    // numbers, for rows and for every kind of error.
    let crlf = format!(
        "{LEGACY_PASS_HEADER}\r\ngrid:8x8,64x64,0,0,false,81,4096,1.0\r\ngrid:8x8,64x64,0,0,false,81,4096,2.0\r\ngrid:8x8,64x64,0,0,false,81,4096,nan\r\n"
    );
    let e = read_passes_from(crlf.as_bytes(), Path::new("c.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("c.csv: line 4, column 8 (pass_time_ns)"), "{e}");
    let e = read_passes_from(crlf.replace("nan", "fast").as_bytes(), Path::new("c.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("c.csv: line 4, column 8 (pass_time_ns)"), "{e}");
    let e = read_passes_from(crlf.replace(",nan", "").as_bytes(), Path::new("c.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("c.csv: line 4, column 0 (row)"), "{e}");
    let rows = read_passes_lines_from(crlf.replace("nan", "3.0").as_bytes(), Path::new("c.csv")).unwrap();
    assert_eq!(rows.iter().map(|(_, l)| *l).collect::<Vec<_>>(), [2, 3, 4]);
    // A quoted cell holding a line break: the line the record starts on.
    let multi = crlf.replace(
        "grid:8x8,64x64,0,0,false,81,4096,2.0",
        "\"grid:\n8x8\",64x64,0,0,false,81,4096,2.0",
    );
    let e = read_passes_from(multi.as_bytes(), Path::new("c.csv"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("c.csv: line 3, column 1 (mesh)") && e.contains("control"),
        "{e}"
    );
}

#[test]
fn appending_writes_the_header_once_and_refuses_another_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.csv");
    std::fs::write(&path, "").unwrap();
    append_passes(&path, &[row("grid:8x8", 0, 1.0)]).unwrap();
    append_passes(&path, &[row("grid:8x8", 5, 2.5)]).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches("mesh,size").count(), 1, "{text}");
    assert_eq!(read_passes(&path).unwrap().len(), 2);
    // A last line without its newline is ended before appending.
    std::fs::write(&path, text.trim_end()).unwrap();
    append_passes(&path, &[row("grid:8x8", 6, 3.0)]).unwrap();
    assert_eq!(read_passes(&path).unwrap().len(), 3);

    let other = dir.path().join("other.csv");
    std::fs::write(&other, "a,b\n1,2\n").unwrap();
    let e = append_passes(&other, &[row("grid:8x8", 0, 1.0)])
        .unwrap_err()
        .to_string();
    assert!(e.contains("other.csv has the header \"a,b\""), "{e}");
    assert_eq!(std::fs::read_to_string(&other).unwrap(), "a,b\n1,2\n");
    assert_eq!(check_appendable(&dir.path().join("new.csv"), 0).unwrap(), AppendTo::New);
}

#[test]
fn the_draws_column_is_written_and_older_files_keep_their_format() {
    let dir = tempfile::tempdir().unwrap();
    // A new file: the header with `draws`, and rows of any draws.
    let path = dir.path().join("p.csv");
    let empty = PassRow {
        draws: 0,
        vs_invocations: 0,
        fs_invocations: 0,
        ..row("grid:8x8", 0, 1.0)
    };
    let split = PassRow {
        draws: 16,
        ..row("grid:8x8", 0, 2.0)
    };
    append_passes(&path, &[empty.clone(), split.clone(), row("grid:8x8", 3, 3.0)]).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with(&format!("{PASS_HEADER}\ngrid:8x8,384x384,0,0,false,0,0,1.0,0\n")),
        "{text}"
    );
    let back = read_passes(&path).unwrap();
    assert_eq!(back, [empty.clone(), split.clone(), row("grid:8x8", 3, 3.0)]);
    assert_eq!(check_appendable(&path, 7).unwrap(), AppendTo::Current);

    // A file of the older header: read as one draw a pass; rows of one
    // draw appended in its format; other draws refused, the file kept.
    let old = dir.path().join("old.csv");
    let before = format!("{LEGACY_PASS_HEADER}\ngrid:8x8,384x384,0,0,false,81,4096,5.0\n");
    std::fs::write(&old, &before).unwrap();
    assert_eq!(read_passes(&old).unwrap()[0].draws, 1);
    append_passes(&old, &[row("grid:8x8", 4, 6.0)]).unwrap();
    let text = std::fs::read_to_string(&old).unwrap();
    assert_eq!(text, format!("{before}grid:8x8,384x384,4,0,false,15570,147456,6.0\n"));
    for r in [&empty, &split] {
        let e = append_passes(&old, &[row("grid:8x8", 5, 7.0), r.clone()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("written before the `draws` column")
                && e.contains(&format!("a pass of {} draws", r.draws))
                && e.contains("old.csv is left as it was"),
            "{e}"
        );
        assert_eq!(std::fs::read_to_string(&old).unwrap(), text);
    }
    assert!(check_appendable(&old, 0).is_err());
    assert_eq!(check_appendable(&old, 1).unwrap(), AppendTo::Legacy);

    // Values no measurement gives, by column.
    let bad = |cells: &str| {
        read_passes_from(format!("{PASS_HEADER}\n{cells}\n").as_bytes(), Path::new("d.csv"))
            .unwrap_err()
            .to_string()
    };
    let e = bad("grid:8x8,64x64,0,0,false,0,0,1.0,4097");
    assert!(
        e.contains("column 9 (draws)") && e.contains("more than 4096 draws"),
        "{e}"
    );
    let e = bad("grid:8x8,64x64,0,0,false,81,0,1.0,0");
    assert!(
        e.contains("column 6 (vs_invocations)") && e.contains("0 draws runs no shader"),
        "{e}"
    );
    let e = bad("grid:8x8,64x64,0,0,false,0,9,1.0,0");
    assert!(e.contains("column 7 (fs_invocations)"), "{e}");
    let e = bad("grid:8x8,64x64,0,0,false,0,0,1.0,-1");
    assert!(e.contains("column 9 (draws)"), "{e}");
    let e = bad("grid:8x8,64x64,0,0,false,0,0,1.0");
    assert!(e.contains("8 fields, expected 9"), "{e}");
}

#[test]
fn only_rebuildable_meshes_are_specs() {
    assert!(is_mesh_spec("grid:96x96:optimized") && is_mesh_spec("corpus/fan10.idx"));
    assert!(!is_mesh_spec("probe") && !is_mesh_spec("grid:axb"));
}

#[test]
fn repeated_passes_pool_their_times() {
    let rows = pool([
        (row("grid:8x8", 0, 0.0), vec![3.0, 1.0]),
        (row("grid:8x8", 9, 0.0), vec![7.0]),
        (row("grid:8x8", 0, 0.0), vec![2.0]),
    ]);
    assert_eq!(rows.len(), 2);
    assert_eq!((rows[0].vs_loops, rows[0].pass_time_ns), (0, 2.0));
    assert_eq!((rows[1].vs_loops, rows[1].pass_time_ns), (9, 7.0));
}
