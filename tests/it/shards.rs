//! Experiments split into shards (`--shard K/N`) and merged (`--merge`)
//! write the very files one process writes (wall-time columns and the
//! timing lines aside); complete shards are kept on a rerun, damaged ones
//! redone; a merge refuses missing, duplicated and mismatched shards by
//! name; `--slurm` writes batch scripts and `--submit` hands them to
//! `sbatch` (a stand-in here; scripts/slurm-test.sh runs a real Slurm).
//! Everything happens inside temp folders the tests create.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn run(args: &[&str]) -> std::process::Output {
    bin().args(args).output().unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

fn err(args: &[&str]) -> String {
    let o = run(args);
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

/// The small noisy experiment of `tests/fixtures/sharded/` (so seeds
/// matter; also run by scripts/slurm-test.sh on a real Slurm), copied into
/// `dir`: per-frame data (a histogram and a derived spread), a line plot, a
/// scatter plot and a check; 3 x 2 points x 2 seeds = 12 runs.
fn experiment(dir: &Path) -> PathBuf {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/sharded");
    for name in ["m.toml", "e.toml"] {
        std::fs::copy(fixtures.join(name), dir.join(name)).unwrap();
    }
    dir.join("e.toml")
}

/// `text` with the cells of the columns whose header starts with
/// `wall_seconds` emptied (CSV without quoted commas, as rendersim writes
/// these files).
fn mask_wall_columns(text: &str) -> String {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let wall: Vec<bool> = header.iter().map(|h| h.starts_with("wall_seconds")).collect();
    let mut out = vec![header.join(",")];
    for l in lines {
        let cells: Vec<&str> = l
            .split(',')
            .enumerate()
            .map(|(i, c)| if wall.get(i) == Some(&true) { "" } else { c })
            .collect();
        out.push(cells.join(","));
    }
    out.join("\n")
}

/// `report.md` without its `## Timing` section (wall and CPU times) and its
/// `## Provenance` (command line and date).
fn without_timing(text: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for l in text.lines() {
        if l.starts_with("## ") {
            skip = l == "## Timing" || l == "## Provenance";
        }
        if !skip {
            out.push_str(l);
            out.push('\n');
        }
    }
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The merged outputs equal the single-process outputs, file by file.
fn assert_same_outputs(single: &Path, merged: &Path) {
    let mut names: Vec<String> = std::fs::read_dir(single)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| !n.starts_with('.'))
        .collect();
    names.sort();
    assert!(names.len() >= 9, "{names:?}");
    for n in &names {
        let a = std::fs::read(single.join(n)).unwrap();
        let b = std::fs::read(merged.join(n)).unwrap_or_else(|e| panic!("merged {n}: {e}"));
        if n.ends_with(".csv") {
            let (a, b) = (String::from_utf8(a).unwrap(), String::from_utf8(b).unwrap());
            assert_eq!(mask_wall_columns(&a), mask_wall_columns(&b), "{n}");
        } else if n == "report.md" {
            let (a, b) = (String::from_utf8(a).unwrap(), String::from_utf8(b).unwrap());
            assert_eq!(without_timing(&a), without_timing(&b), "{n}");
            assert!(b.contains("- array wall time: "), "{b}");
            assert!(b.contains("3 shards"), "{b}");
            assert!(b.contains("- total CPU time over all shards: "), "{b}");
            assert!(a.contains("- CPU time: "), "{a}");
        } else {
            assert!(a == b, "{n} differs");
        }
    }
}

#[test]
fn merged_shards_write_what_one_process_writes() {
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let single = d.path().join("single");
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&single)]);
    let out = d.path().join("sharded");
    for k in 1..=3 {
        let line = ok(&[
            "experiment",
            s(&exp),
            "--quiet",
            "--out",
            s(&out),
            "--shard",
            &format!("{k}/3"),
        ]);
        assert!(line.contains(&format!("shard {k}/3: 4 runs")), "{line}");
    }
    let shard2 = out.join("shards/shard-2-of-3.json");
    assert!(shard2.is_file());
    let merged = ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    assert!(merged.contains("from 3 shards"), "{merged}");
    assert_same_outputs(&single, &out);
    // The shard files stay beside the merged outputs; merging again works.
    assert!(shard2.is_file());
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    assert_same_outputs(&single, &out);

    // A complete shard is kept when run again.
    let before = std::fs::read(&shard2).unwrap();
    let again = ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "2/3"]);
    assert!(again.contains("already complete"), "{again}");
    assert_eq!(std::fs::read(&shard2).unwrap(), before);
    // A damaged one (half a file) is redone, and the merge is whole again.
    std::fs::write(&shard2, &before[..before.len() / 2]).unwrap();
    let e = err(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    assert!(
        e.contains("shard-2-of-3.json") && e.contains("not a readable shard file"),
        "{e}"
    );
    let o = run(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "2/3"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("redone"));
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    assert_same_outputs(&single, &out);
}

#[test]
fn a_merge_refuses_missing_duplicated_and_mismatched_shards() {
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let out = d.path().join("out");
    let merge = || err(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    let e = merge();
    assert!(e.contains("no shard files"), "{e}");
    for k in [1, 3] {
        ok(&[
            "experiment",
            s(&exp),
            "--quiet",
            "--out",
            s(&out),
            "--shard",
            &format!("{k}/3"),
        ]);
    }
    let e = merge();
    assert!(e.contains("1 of 3 shards missing: shard-2-of-3.json"), "{e}");
    assert!(e.contains("on Slurm `sbatch --array=2 job.sbatch`"), "{e}");
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "2/3"]);
    let shards = out.join("shards");
    // Twice: a copy under another name.
    std::fs::copy(shards.join("shard-2-of-3.json"), shards.join("copy.json")).unwrap();
    let e = merge();
    assert!(e.contains("shard 2/3 is there twice") && e.contains("copy.json"), "{e}");
    std::fs::remove_file(shards.join("copy.json")).unwrap();
    // A shard of another split.
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "1/2"]);
    let e = merge();
    assert!(
        e.contains("two different splits") && e.contains("shard-1-of-2.json"),
        "{e}"
    );
    std::fs::remove_file(shards.join("shard-1-of-2.json")).unwrap();
    // Another rendersim version.
    let p = shards.join("shard-3-of-3.json");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(
        &p,
        text.replace("\"rendersim_version\":\"", "\"rendersim_version\":\"9"),
    )
    .unwrap();
    let e = merge();
    assert!(e.contains("shard-3-of-3.json: made by rendersim 9"), "{e}");
    std::fs::write(&p, &text).unwrap();
    ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    // The experiment file changed since the shards ran.
    let t = std::fs::read_to_string(&exp).unwrap();
    std::fs::write(&exp, t.replace("bins = 20", "bins = 21")).unwrap();
    let e = merge();
    assert!(e.contains("shard-1-of-3.json: made from a different experiment"), "{e}");
    // The earlier merged outputs are untouched by the refused merges.
    assert!(out.join("report.md").is_file());
    // A shard run again after the change is redone, not kept.
    let o = run(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "1/3"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("made from a different experiment"));
}

#[test]
fn shard_options_are_checked() {
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let out = d.path().join("out");
    for (bad, says) in [
        ("0/3", "needs 1 <= K <= N"),
        ("4/3", "needs 1 <= K <= N"),
        ("two/3", "is not K/N"),
        ("3", "is not K/N"),
    ] {
        let e = err(&["experiment", s(&exp), "--out", s(&out), "--shard", bad]);
        assert!(e.contains(says), "{bad}: {e}");
    }
    // More shards than runs: refused before the folder is made (a merge
    // would otherwise size its bookkeeping by N).
    for bad in ["1/13", "1/4294967296"] {
        let e = err(&["experiment", s(&exp), "--out", s(&out), "--shard", bad]);
        assert!(
            e.contains("for an experiment of 12 runs; N can be at most 12"),
            "{bad}: {e}"
        );
        assert!(!out.exists(), "{bad}");
    }
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--shard", "1/2", "--merge"]);
    assert!(e.contains("cannot be used with"), "{e}");
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--shards", "4"]);
    assert!(e.contains("--slurm"), "{e}");
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--slurm", "--shards", "13"]);
    assert!(e.contains("more shards than the experiment's 12 runs"), "{e}");
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--slurm", "--time", "1h"]);
    assert!(e.contains("--time \"1h\"") && e.contains("D-HH:MM:SS"), "{e}");
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--slurm", "--partition", "a b"]);
    assert!(e.contains("--partition \"a b\""), "{e}");
    // A folder holding other files is refused before anything runs.
    let mine = d.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("thesis.tex"), "x").unwrap();
    let e = err(&["experiment", s(&exp), "--out", s(&mine), "--shard", "1/2"]);
    assert!(e.contains("thesis.tex"), "{e}");
}

#[cfg(unix)]
#[test]
fn slurm_writes_an_array_and_a_merge_and_submit_chains_them() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let out = d.path().join("out");
    let said = ok(&[
        "experiment",
        s(&exp),
        "--out",
        s(&out),
        "--slurm",
        "--shards",
        "4",
        "--partition",
        "short",
        "--time",
        "10:00",
        "--cpus-per-task",
        "2",
        "--throttle",
        "2",
        "--slurm-opt=--account=proj",
        "--slurm-opt",
        "--mem=4G",
        "--slurm-opt",
        "-q short",
    ]);
    assert!(said.contains("sbatch --dependency=afterany:"), "{said}");
    let job = std::fs::read_to_string(out.join("job.sbatch")).unwrap();
    for line in [
        "#SBATCH --array=1-4%2\n",
        "#SBATCH --account=proj\n",
        "#SBATCH --mem=4G\n",
        "#SBATCH -q short\n",
        "#SBATCH --partition=short\n",
        "#SBATCH --time=10:00\n",
        "#SBATCH --cpus-per-task=2\n",
        "--shard \"${SLURM_ARRAY_TASK_ID}/4\"",
        "RAYON_NUM_THREADS",
    ] {
        assert!(job.contains(line), "{line} not in\n{job}");
    }
    assert!(
        job.contains(&format!("--out '{}'", out.canonicalize().unwrap().display())),
        "{job}"
    );
    let merge = std::fs::read_to_string(out.join("merge.sbatch")).unwrap();
    assert!(
        merge.contains(" --merge") && !merge.contains("#SBATCH --array"),
        "{merge}"
    );
    assert!(
        merge.contains("#SBATCH --account=proj\n") && merge.contains("#SBATCH --mem=4G\n"),
        "{merge}"
    );
    // Options the scripts set themselves, or that are not options, are refused
    // before anything is written.
    for (opt, says) in [
        ("--slurm-opt=--array=1-9", "use --shards and --throttle"),
        ("--slurm-opt=account=proj", "an sbatch option"),
    ] {
        let e = err(&["experiment", s(&exp), "--out", s(&out), "--slurm", opt]);
        assert!(e.contains(says), "{e}");
        let fresh = d.path().join("fresh");
        err(&["experiment", s(&exp), "--out", s(&fresh), "--slurm", opt]);
        assert!(!fresh.exists(), "nothing made for a refused option");
    }
    let e = err(&["experiment", s(&exp), "--out", s(&out), "--slurm", "--throttle", "0"]);
    assert!(e.contains("--throttle \"0\"") && e.contains("at least 1"), "{e}");
    assert!(out.join("logs").is_dir());

    // --submit with a stand-in sbatch that logs its arguments and answers ids.
    let log = d.path().join("sbatch.log");
    let fake = d.path().join("sbatch");
    std::fs::write(
        &fake,
        format!(
            "#!/bin/sh\necho \"$@\" >> '{}'\nn=$(wc -l < '{}')\necho \"$((100 + n));cluster\"\n",
            log.display(),
            log.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let o = bin()
        .args([
            "experiment",
            s(&exp),
            "--out",
            s(&out),
            "--slurm",
            "--shards",
            "4",
            "--submit",
        ])
        .env("RENDERSIM_SBATCH", &fake)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        said.contains("submitted array job 101 (4 tasks) and merge job 102"),
        "{said}"
    );
    let calls = std::fs::read_to_string(&log).unwrap();
    let calls: Vec<&str> = calls.lines().collect();
    assert_eq!(calls.len(), 2);
    assert!(
        calls[0].starts_with("--parsable ") && calls[0].ends_with("job.sbatch"),
        "{calls:?}"
    );
    assert!(
        calls[1].contains("--dependency=afterany:101 ") && calls[1].ends_with("merge.sbatch"),
        "{calls:?}"
    );
    // sbatch refusing is an error that says so.
    std::fs::write(
        &fake,
        "#!/bin/sh\necho 'sbatch: error: invalid partition' >&2\nexit 1\n",
    )
    .unwrap();
    let o = bin()
        .args(["experiment", s(&exp), "--out", s(&out), "--slurm", "--submit"])
        .env("RENDERSIM_SBATCH", &fake)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("invalid partition") && e.contains("job.sbatch"), "{e}");
}

/// Shard files are read back like user input: counts bounded by the
/// experiment before anything is sized by them, every run checked against
/// the checksum written with it, so an edited file is neither merged nor
/// taken as complete on a rerun.
#[test]
fn edited_shard_files_are_refused_and_redone() {
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let out = d.path().join("out");
    for k in 1..=3 {
        ok(&[
            "experiment",
            s(&exp),
            "--quiet",
            "--out",
            s(&out),
            "--shard",
            &format!("{k}/3"),
        ]);
    }
    let merge = || err(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    let shards = out.join("shards");
    let names: Vec<PathBuf> = (1..=3).map(|k| shards.join(format!("shard-{k}-of-3.json"))).collect();
    let texts: Vec<String> = names.iter().map(|p| std::fs::read_to_string(p).unwrap()).collect();
    let restore = || {
        for (p, t) in names.iter().zip(&texts) {
            std::fs::write(p, t).unwrap();
        }
    };
    // A shard count far beyond the runs, in every file (no allocation by it).
    for (p, t) in names.iter().zip(&texts) {
        std::fs::write(p, t.replace("\"shards\":3", "\"shards\":1000000000")).unwrap();
    }
    let e = merge();
    assert!(
        e.contains("shard-1-of-3.json") && e.contains("one of 1000000000 shards") && e.contains("1 to 12"),
        "{e}"
    );
    restore();
    // The whole experiment's run count edited.
    std::fs::write(
        &names[1],
        texts[1].replace("\"total_runs\":12", "\"total_runs\":4000000000"),
    )
    .unwrap();
    let e = merge();
    assert!(e.contains("shard-2-of-3.json") && e.contains("4000000000 runs"), "{e}");
    restore();
    // A time that is not a number of seconds.
    let t = &texts[2];
    let start = t.find("\"cpu_seconds\":").unwrap();
    let end = start + t[start..].find(',').unwrap();
    std::fs::write(&names[2], format!("{}\"cpu_seconds\":-1{}", &t[..start], &t[end..])).unwrap();
    let e = merge();
    assert!(
        e.contains("shard-3-of-3.json") && e.contains("`cpu_seconds` is -1"),
        "{e}"
    );
    restore();
    // A tracked value edited to NaN, inf, an overflow, or just another
    // number: the runs no longer match their checksum.
    let first_value = |t: &str| {
        let at = t.find("\"values\":\"").unwrap() + "\"values\":\"".len();
        let len = t[at..].find([' ', '"']).unwrap();
        (at, len)
    };
    for edit in ["NaN", "inf", "1e400", "2.5e1"] {
        let (at, len) = first_value(&texts[1]);
        let edited = format!("{}{edit}{}", &texts[1][..at], &texts[1][at + len..]);
        std::fs::write(&names[1], &edited).unwrap();
        let e = merge();
        assert!(
            e.contains("shard-2-of-3.json") && e.contains("checksum") && e.contains("edited"),
            "{edit}: {e}"
        );
        // A rerun of the edited shard redoes it instead of calling it complete.
        let o = run(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--shard", "2/3"]);
        assert!(o.status.success(), "{edit}");
        let (stdout, stderr) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(!stdout.contains("already complete"), "{edit}: {stdout}");
        assert!(
            stderr.contains("redone") && stderr.contains("checksum"),
            "{edit}: {stderr}"
        );
        ok(&["experiment", s(&exp), "--quiet", "--out", s(&out), "--merge"]);
    }
    // The rerun wrote the same values (same seeds, same bits) as the first time.
    let now = std::fs::read_to_string(&names[1]).unwrap();
    let values = |t: &str| {
        t.split("\"values\":\"")
            .skip(1)
            .map(|v| v[..v.find('"').unwrap()].to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(values(&now), values(&texts[1]));
    assert_eq!(values(&now).len(), 4);
}

#[cfg(unix)]
#[test]
fn the_printed_submit_line_runs_nothing_a_folder_name_holds() {
    // Issue 60 item 10: the `submit with:` line quotes the scripts' paths,
    // so pasting it for an --out like `a$(touch${IFS}pwned)` runs only sbatch.
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let exp = experiment(d.path());
    let out = d.path().join("a$(touch${IFS}pwned)");
    let said = ok(&["experiment", s(&exp), "--out", s(&out), "--slurm", "--shards", "2"]);
    let line = said
        .lines()
        .find_map(|l| l.strip_prefix("submit with: "))
        .unwrap_or_else(|| panic!("no submit line in {said}"));
    let stub = d.path().join("bin");
    std::fs::create_dir(&stub).unwrap();
    let sbatch = stub.join("sbatch");
    std::fs::write(&sbatch, "#!/bin/sh\necho 7\n").unwrap();
    std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", stub.display(), std::env::var("PATH").unwrap_or_default());
    let st = std::process::Command::new("sh")
        .args(["-c", line])
        .current_dir(d.path())
        .env("PATH", path)
        .status()
        .unwrap();
    assert!(st.success(), "{line}");
    assert!(!d.path().join("pwned").exists(), "the line ran the folder name: {line}");
}
