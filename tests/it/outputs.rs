//! Outputs never damage what their paths name, and result sets are atomic
//! as sets: FIFOs and links stay what they are, a folder holding other files
//! is refused before any simulation, and a kill at any moment of a run or an
//! experiment leaves the earlier results whole. Everything happens inside
//! temp folders the tests create.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn model(dir: &Path) -> String {
    let p = dir.join("m.toml");
    std::fs::write(
        &p,
        "[run]\nframes = 20\n[noise]\nenabled = false\n[workload]\nkind = \"fixed\"\ncpu = \"2ms\"\ngpu = \"9ms\"\n",
    )
    .unwrap();
    p.display().to_string()
}

/// `rendersim experiment FILE --quiet --out DIR`.
fn experiment(file: &Path, out: &Path) -> Command {
    let mut c = bin();
    c.args([
        "experiment",
        file.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    c
}

fn ok(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    String::from_utf8(o.stdout).unwrap()
}

fn err(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// Every file under `dir` with its bytes, sorted by name.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().to_string(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// Names in `dir` that start with `.NAME.` (staging and swapped-out folders).
fn leftovers(dir: &Path, name: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with(&format!(".{name}.")))
        .collect()
}

#[cfg(unix)]
fn mkfifo(p: &Path) {
    let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path inside a temp folder.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

#[cfg(unix)]
fn is_fifo(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).unwrap().file_type().is_fifo()
}

#[cfg(unix)]
fn signal(child: &Child, sig: i32) {
    // SAFETY: sending a signal to our own child process.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, sig) }, 0);
}

/// Polls until `cond` holds (the process under test gets there by itself;
/// the bound only keeps a broken build from hanging the suite).
fn wait_for(what: &str, mut cond: impl FnMut() -> bool) {
    for _ in 0..6000 {
        if cond() {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("never happened: {what}");
}

#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_quietly_without_a_panic() {
    let d = tempfile::tempdir().unwrap();
    let mut child = bin()
        .args(["run", &model(d.path()), "--trace", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes away at once, like `| head -c 0`.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(out.status.code(), Some(101), "{err}");
}

#[test]
fn a_trace_on_standard_output_is_the_whole_output() {
    let d = tempfile::tempdir().unwrap();
    let out = ok(bin().args(["run", &model(d.path()), "--trace", "-"]));
    let v: serde_json::Value = serde_json::from_str(&out).expect("stdout is the trace alone");
    assert!(v["traceEvents"].as_array().unwrap().len() > 20);
}

#[cfg(unix)]
#[test]
fn a_trace_into_a_fifo_arrives_whole_and_the_fifo_stays_a_fifo() {
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("trace.pipe");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(&fifo).unwrap())
    };
    ok(bin().args(["run", &model(d.path()), "--trace", fifo.to_str().unwrap()]));
    let bytes = reader.join().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&bytes).expect("the reader got the whole trace");
    assert!(v["traceEvents"].as_array().unwrap().len() > 20);
    assert!(is_fifo(&fifo), "the FIFO was replaced");
}

#[cfg(unix)]
#[test]
fn a_trace_through_a_link_replaces_the_target_and_keeps_the_link() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("real.json"), "old").unwrap();
    let link = d.path().join("trace.json");
    std::os::unix::fs::symlink("real.json", &link).unwrap();
    ok(bin().args(["run", &model(d.path()), "--trace", link.to_str().unwrap()]));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(d.path().join("real.json")).unwrap()).unwrap();
    assert!(v["traceEvents"].is_array());
    // A folder as the trace is refused before the run.
    let e = err(bin().args(["run", &model(d.path()), "--trace", d.path().to_str().unwrap()]));
    assert!(e.contains("is a folder"), "{e}");
}

#[test]
fn out_refuses_a_folder_holding_other_files_before_simulating() {
    let d = tempfile::tempdir().unwrap();
    let mine = d.path().join("thesis");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("chapter1.tex"), "years of work").unwrap();
    let m = model(d.path());
    let e = err(bin().args(["run", &m, "--frames", "100000000", "--out", mine.to_str().unwrap()]));
    assert!(
        e.contains("chapter1.tex") && e.contains("rendersim did not write"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("chapter1.tex")).unwrap(),
        "years of work"
    );
    // Under a file, a folder cannot be made: also before simulating.
    let e = err(bin().args([
        "run",
        &m,
        "--frames",
        "100000000",
        "--out",
        mine.join("chapter1.tex/out").to_str().unwrap(),
    ]));
    assert!(e.contains("chapter1.tex"), "{e}");
    // An experiment likewise.
    let exp = d.path().join("e.toml");
    std::fs::write(
        &exp,
        "name = \"e\"\nmodel = \"m.toml\"\n[[metric]]\npath = \"frames\"\n",
    )
    .unwrap();
    let e = err(&mut experiment(&exp, &mine));
    assert!(e.contains("chapter1.tex"), "{e}");
}

#[test]
fn a_rerun_replaces_the_whole_set_and_leaves_nothing_beside_it() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let out = d.path().join("out");
    ok(bin().args(["run", &m, "--seed", "1", "--out", out.to_str().unwrap()]));
    let first = snapshot(&out);
    let names: Vec<&str> = first.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, [".rendersim-set", "frames.csv", "model.toml", "summary.json"]);
    ok(bin().args(["run", &m, "--seed", "2", "--out", out.to_str().unwrap()]));
    let second = snapshot(&out);
    assert_ne!(first, second);
    assert!(leftovers(d.path(), "out").is_empty());
    // A folder written by an older rendersim (no marker, only its files) is accepted.
    std::fs::remove_file(out.join(".rendersim-set")).unwrap();
    ok(bin().args(["run", &m, "--out", out.to_str().unwrap()]));
}

/// Starts `run --out DIR` held by `RENDERSIM_HOLD_BEFORE_SWAP` with its new
/// set fully staged, just before the swap: the last moment of its write phase.
#[cfg(unix)]
fn start_run_held_in_its_write_phase(d: &Path, out: &Path) -> (Child, PathBuf) {
    let flag = d.join("held");
    let _ = std::fs::remove_file(&flag);
    let child = bin()
        .args(["run", &model(d), "--seed", "2", "--out", out.to_str().unwrap()])
        .env("RENDERSIM_HOLD_BEFORE_SWAP", &flag)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let staging = out.with_file_name(format!(".out.partial-{}", child.id()));
    wait_for("the new set staged", || flag.exists());
    for f in ["summary.json", "frames.csv", "model.toml", ".rendersim-set"] {
        assert!(staging.join(f).exists(), "{f} staged");
    }
    (child, staging)
}

#[cfg(unix)]
#[test]
fn a_kill_in_the_write_phase_of_a_run_leaves_the_old_set() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    ok(bin().args(["run", &model(d.path()), "--seed", "1", "--out", out.to_str().unwrap()]));
    let old = snapshot(&out);

    // SIGTERM (and SIGINT alike): the staging folder is removed.
    let (mut child, staging) = start_run_held_in_its_write_phase(d.path(), &out);
    signal(&child, libc::SIGTERM);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(128 + libc::SIGTERM));
    assert_eq!(snapshot(&out), old);
    assert!(!staging.exists(), "staging removed on SIGTERM");
    assert!(leftovers(d.path(), "out").is_empty());

    // SIGKILL cannot be caught: the old set stays; the next run clears the staging left behind.
    let (mut child, staging) = start_run_held_in_its_write_phase(d.path(), &out);
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(snapshot(&out), old);
    assert!(staging.exists());
    ok(bin().args(["run", &model(d.path()), "--seed", "3", "--out", out.to_str().unwrap()]));
    assert!(!staging.exists(), "stale staging removed");
    assert_ne!(snapshot(&out), old);
    assert!(leftovers(d.path(), "out").is_empty());

    // Released instead of killed, the held run swaps its set in.
    let (mut child, _) = start_run_held_in_its_write_phase(d.path(), &out);
    std::fs::remove_file(d.path().join("held")).unwrap();
    assert!(child.wait().unwrap().success());
    let seed2 = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(seed2.contains("\"seed\": 2"), "{seed2}");
    assert!(leftovers(d.path(), "out").is_empty());
}

#[cfg(unix)]
#[test]
fn a_kill_during_an_experiment_leaves_the_old_set() {
    let d = tempfile::tempdir().unwrap();
    model(d.path());
    let exp = d.path().join("e.toml");
    let write_exp = |replications: u32| {
        std::fs::write(
            &exp,
            format!(
                "name = \"e\"\nmodel = \"m.toml\"\nreplications = {replications}\n[set]\n\"run.frames\" = 2000\n\
                 [[metric]]\npath = \"metrics.frame_time_ms.mean\"\n"
            ),
        )
        .unwrap()
    };
    let out = d.path().join("out");
    write_exp(2);
    ok(&mut experiment(&exp, &out));
    let old = snapshot(&out);
    assert!(old.iter().any(|(n, _)| n == "runs.csv"));

    write_exp(400);
    let mut child = experiment(&exp, &out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let staging = d.path().join(format!(".out.partial-{}", child.id()));
    // (Or its end, should it finish first on a fast machine.)
    let mut ended = None;
    wait_for("the staging folder", || {
        ended = child.try_wait().unwrap();
        staging.exists() || ended.is_some()
    });
    if ended.is_none() {
        signal(&child, libc::SIGINT);
    }
    let status = ended.unwrap_or_else(|| child.wait().unwrap());
    if status.code() == Some(128 + libc::SIGINT) {
        assert_eq!(snapshot(&out), old, "the old set, whole");
    } else {
        // It finished before the signal landed: then the new set, whole.
        assert!(status.success());
        let runs_bytes =
            |set: &[(String, Vec<u8>)]| set.iter().find(|(n, _)| n == "runs.csv").map_or(0, |(_, b)| b.len());
        // 400 replications against the old 2: a longer runs.csv.
        assert!(runs_bytes(&snapshot(&out)) > runs_bytes(&old));
    }
    assert!(leftovers(d.path(), "out").is_empty());
}

#[test]
fn a_failed_experiment_keeps_the_old_set_and_puts_finished_runs_beside_it() {
    let d = tempfile::tempdir().unwrap();
    model(d.path());
    let exp = d.path().join("e.toml");
    let out = d.path().join("out");
    std::fs::write(
        &exp,
        "name = \"e\"\nmodel = \"m.toml\"\n[[sweep]]\nkey = \"workload.gpu\"\nvalues = [\"5ms\", \"9ms\"]\n\
         [[metric]]\npath = \"metrics.frame_time_ms.mean\"\n",
    )
    .unwrap();
    ok(&mut experiment(&exp, &out));
    let old = snapshot(&out);
    // The second point now fails when it runs (a metric it does not have).
    std::fs::write(
        &exp,
        "name = \"e\"\nmodel = \"m.toml\"\n[[sweep]]\nkey = \"workload.gpu\"\nvalues = [\"5ms\", \"9ms\"]\n\
         [[metric]]\npath = \"metrics.no_such_metric\"\n",
    )
    .unwrap();
    let e = err(&mut experiment(&exp, &out));
    assert!(e.contains("unchanged"), "{e}");
    assert_eq!(snapshot(&out), old);
    assert!(leftovers(d.path(), "out").is_empty());
}

/// A trace path that is a link to this process's standard output (what
/// `/dev/stdout` is), made inside a temp folder: written in place, whether
/// stdout is a pipe or a file the caller redirected it to; the link stays.
#[cfg(target_os = "linux")]
#[test]
fn a_trace_through_a_link_to_standard_output_is_written_in_place() {
    let d = tempfile::tempdir().unwrap();
    let link = d.path().join("stdout-link");
    std::os::unix::fs::symlink("/proc/self/fd/1", &link).unwrap();
    // Standard output a pipe.
    let out = ok(bin().args(["run", &model(d.path()), "--trace", link.to_str().unwrap()]));
    let v: serde_json::Value = serde_json::from_str(&out).expect("stdout is the trace alone");
    assert!(v["traceEvents"].as_array().unwrap().len() > 20);
    // Standard output redirected to a file.
    let file = d.path().join("redirected.json");
    let status = bin()
        .args(["run", &model(d.path()), "--json", "--trace", link.to_str().unwrap()])
        .stdout(std::fs::File::create(&file).unwrap())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(status.status.success());
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&file).unwrap()).expect("the file is the trace alone");
    assert!(v["traceEvents"].as_array().unwrap().len() > 20);
    // The JSON summary went to standard error instead.
    let err = String::from_utf8_lossy(&status.stderr);
    assert!(err.contains("\"metrics\""), "{err}");
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    let mut names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    assert_eq!(names, ["m.toml", "redirected.json", "stdout-link"]);
}

// --- A set is one thing; nothing is left behind (issue 29) ---

/// Every name under `dir`, folders included, relative to it (sorted).
fn tree(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).unwrap() {
            let e = e.unwrap();
            out.push(e.path().strip_prefix(dir).unwrap().display().to_string());
            if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn a_trace_that_names_a_file_of_the_set_is_refused_before_simulating() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let out = d.path().join("out");
    let o = out.to_str().unwrap();
    ok(bin().args(["run", &m, "--seed", "1", "--out", o]));
    let old = snapshot(&out);
    for name in [
        "summary.json",
        "frames.csv",
        "model.toml",
        ".rendersim-set",
        "./summary.json",
        "../out/frames.csv",
        "sub/../model.toml",
    ] {
        let trace = format!("{o}/{name}");
        let e = err(bin().args(["run", &m, "--frames", "10000000", "--out", o, "--trace", &trace]));
        assert!(
            e.contains("is the result set's own") && e.contains(&trace),
            "{name}: {e}"
        );
        assert_eq!(snapshot(&out), old, "{name}: the old set is untouched");
        assert!(leftovers(d.path(), "out").is_empty(), "{name}");
    }
    // The folder itself is not a file.
    let e = err(bin().args(["run", &m, "--out", o, "--trace", o]));
    assert!(e.contains("is a folder"), "{e}");
    // Any other name inside the set goes through the set's commit, in a
    // subfolder too, and the set's own files are all there beside it.
    ok(bin().args([
        "run",
        &m,
        "--seed",
        "2",
        "--out",
        o,
        "--trace",
        &format!("{o}/trace.json"),
    ]));
    ok(bin().args([
        "run",
        &m,
        "--seed",
        "3",
        "--out",
        o,
        "--trace",
        &format!("{o}/t/run.json"),
    ]));
    assert_eq!(
        tree(&out),
        [
            ".rendersim-set",
            "frames.csv",
            "model.toml",
            "summary.json",
            "t",
            "t/run.json"
        ],
        "the earlier set (with trace.json) was replaced whole"
    );
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("t/run.json")).unwrap()).unwrap();
    assert!(v["traceEvents"].as_array().unwrap().len() > 20);
    assert!(leftovers(d.path(), "out").is_empty());
}

#[cfg(unix)]
#[test]
fn a_read_only_set_folder_is_refused_before_simulating() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let out = d.path().join("out");
    let o = out.to_str().unwrap();
    ok(bin().args(["run", &m, "--seed", "1", "--out", o]));
    let old = snapshot(&out);
    let set_mode = |mode| std::fs::set_permissions(&out, std::fs::Permissions::from_mode(mode)).unwrap();
    set_mode(0o555);
    let e = err(bin().args(["run", &m, "--frames", "10000000", "--out", o]));
    assert!(e.contains("is read-only") && e.contains(o), "{e}");
    set_mode(0o755);
    assert_eq!(snapshot(&out), old);
    assert!(leftovers(d.path(), "out").is_empty());
    // A read-only folder inside a set (an experiment's plots, say) too.
    let sub = out.join("plots");
    std::fs::create_dir(&sub).unwrap();
    std::fs::set_permissions(&sub, std::fs::Permissions::from_mode(0o555)).unwrap();
    let e = err(bin().args(["run", &m, "--out", o]));
    assert!(e.contains("is read-only") && e.contains("plots"), "{e}");
    std::fs::set_permissions(&sub, std::fs::Permissions::from_mode(0o755)).unwrap();
    ok(bin().args(["run", &m, "--out", o]));
    assert!(leftovers(d.path(), "out").is_empty());
}

/// `.NAME.tmp-PID` and `.NAME.partial-PID` names in `dir`.
fn temps(dir: &Path) -> Vec<String> {
    tree(dir)
        .into_iter()
        .filter(|n| n.contains(".tmp-") || n.contains(".partial-") || n.contains(".old-"))
        .collect()
}

#[cfg(unix)]
#[test]
fn a_killed_trace_writer_leaves_a_temp_file_that_the_next_run_removes() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let trace = d.path().join("trace.json");
    let t = trace.to_str().unwrap();
    let mut child = bin()
        .args(["run", &m, "--frames", "10000000", "--trace", t])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let tmp = d.path().join(format!(".trace.json.tmp-{}", child.id()));
    wait_for("the trace's temporary file", || tmp.exists());
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(tmp.exists(), "SIGKILL cannot be caught");
    // A temporary file of a process that still runs is not touched (this
    // test's own process stands for one).
    let live = d.path().join(format!(".trace.json.tmp-{}", std::process::id()));
    std::fs::write(&live, "another writer's").unwrap();
    ok(bin().args(["run", &m, "--trace", t]));
    assert!(!tmp.exists(), "the dead writer's temporary file is removed");
    assert!(live.exists());
    std::fs::remove_file(&live).unwrap();
    assert!(temps(d.path()).is_empty(), "{:?}", temps(d.path()));
}

/// SIGTERM at spread moments of runs that write a set and a trace (the
/// commit window included): nothing temporary is ever left, and the set is
/// the old one or the new one, whole.
#[cfg(unix)]
#[test]
fn sigterm_at_any_moment_leaves_no_temporary_file() {
    use rand::{Rng, SeedableRng};
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let out = d.path().join("out");
    let o = out.to_str().unwrap();
    let trace = d.path().join("trace.json");
    ok(bin().args(["run", &m, "--out", o, "--trace", trace.to_str().unwrap()]));
    let names = [".rendersim-set", "frames.csv", "model.toml", "summary.json"];
    // How long one run takes here, to spread the signals over it.
    let t0 = std::time::Instant::now();
    ok(bin().args([
        "run",
        &m,
        "--frames",
        "3000",
        "--out",
        o,
        "--trace",
        trace.to_str().unwrap(),
    ]));
    let span = t0.elapsed().as_micros().max(1000) as u64;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(29);
    let mut ended_by_signal = 0;
    for i in 0..40 {
        let inside = i % 2 == 0;
        let trace_path = if inside {
            format!("{o}/trace.json")
        } else {
            trace.to_str().unwrap().to_string()
        };
        let mut child = bin()
            .args(["run", &m, "--frames", "3000", "--out", o, "--trace", &trace_path])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_micros(rng.random_range(0..span + span / 4)));
        signal(&child, libc::SIGTERM);
        let status = child.wait().unwrap();
        use std::os::unix::process::ExitStatusExt;
        if status.code() == Some(128 + libc::SIGTERM) {
            ended_by_signal += 1;
        } else if status.signal() == Some(libc::SIGTERM) {
            // Ended before its handler was in place: it had written nothing.
        } else {
            assert!(status.success(), "trial {i}: {status:?}");
        }
        assert!(temps(d.path()).is_empty(), "trial {i}: {:?}", temps(d.path()));
        let files: Vec<String> = snapshot(&out).into_iter().map(|(n, _)| n).collect();
        let mut want: Vec<&str> = names.to_vec();
        if files.iter().any(|n| n == "trace.json") {
            want.push("trace.json");
            want.sort();
        }
        assert_eq!(files, want, "trial {i}: a whole set");
    }
    assert!(ended_by_signal > 0, "no run was interrupted: the spread is off");
}

/// Runs started at once into one absent folder all succeed, and leave one
/// whole set and nothing else.
#[test]
fn concurrent_runs_into_an_absent_folder_all_succeed() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    for trial in 0..8 {
        let parent = d.path().join(format!("t{trial}"));
        let out = parent.join("new/out");
        let children: Vec<Child> = (0..6)
            .map(|seed| {
                bin()
                    .args(["run", &m, "--seed", &seed.to_string(), "--out", out.to_str().unwrap()])
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            assert!(
                o.status.success(),
                "trial {trial}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let files: Vec<String> = snapshot(&out).into_iter().map(|(n, _)| n).collect();
        assert_eq!(files, [".rendersim-set", "frames.csv", "model.toml", "summary.json"]);
        assert_eq!(
            tree(&parent.join("new")),
            [
                "out",
                "out/.rendersim-set",
                "out/frames.csv",
                "out/model.toml",
                "out/summary.json"
            ]
        );
    }
}

#[test]
fn an_output_that_names_an_input_or_another_output_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let before = std::fs::read(&m).unwrap();
    let e = err(bin().args(["run", &m, "--trace", &m]));
    assert!(
        e.contains("--trace") && e.contains("names the same file as MODEL"),
        "{e}"
    );
    let e = err(bin().args([
        "run",
        &m,
        "--trace",
        &format!("{m}/../../{}/m.toml", d.path().file_name().unwrap().to_str().unwrap()),
    ]));
    assert!(e.contains("names the same file as MODEL"), "{e}");
    assert_eq!(std::fs::read(&m).unwrap(), before, "the model file is as it was");
    let csv = d.path().join("passes.csv");
    std::fs::write(
        &csv,
        "mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns\n",
    )
    .unwrap();
    let c = csv.to_str().unwrap();
    let e = err(bin().args(["calibrate", c, "--out", c]));
    assert!(e.contains("--out") && e.contains("names the same file as FILES"), "{e}");
    let p = d.path().join("p.toml");
    let e = err(bin().args([
        "calibrate",
        c,
        "--out",
        p.to_str().unwrap(),
        "--report",
        p.to_str().unwrap(),
    ]));
    assert!(
        e.contains("--report") && e.contains("names the same file as --out"),
        "{e}"
    );
    assert!(
        std::fs::read_to_string(&csv).unwrap().starts_with("mesh,size"),
        "the input is as it was"
    );
}

/// The git revision of this checkout, when it is one and git runs.
fn checkout_revision() -> Option<String> {
    let o = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    o.status
        .success()
        .then(|| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

#[test]
fn run_replay_and_experiment_outputs_say_where_they_came_from() {
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let out = d.path().join("out");
    // SOURCE_DATE_EPOCH fixes the date (reproducible outputs).
    ok(bin().env("SOURCE_DATE_EPOCH", "1796386922").args([
        "run",
        &m,
        "--set",
        "run.frames=5",
        "--out",
        out.to_str().unwrap(),
    ]));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let p = &summary["provenance"];
    assert_eq!(p["program"], format!("rendersim {}", env!("CARGO_PKG_VERSION")), "{p}");
    assert_eq!(p["date"], "2026-12-04T12:22:02Z");
    let command: Vec<&str> = p["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    assert_eq!(
        command[1..],
        [
            "run",
            m.as_str(),
            "--set",
            "run.frames=5",
            "--out",
            out.to_str().unwrap()
        ]
    );
    // Built in a git checkout, the revision is this checkout's (maybe dirty).
    if let Some(rev) = checkout_revision() {
        let got = p["git_revision"].as_str().unwrap_or_else(|| panic!("no revision: {p}"));
        assert!(got == rev || got == format!("{rev}-dirty"), "{got} against {rev}");
    }
    // The model file's head says the same, and the file still runs.
    let text = std::fs::read_to_string(out.join("model.toml")).unwrap();
    let head: Vec<&str> = text.lines().take(2).collect();
    assert!(
        head[0].starts_with("# Written by rendersim ") && head[0].ends_with(", 2026-12-04T12:22:02Z"),
        "{text}"
    );
    assert!(
        head[1].starts_with("# Command: ") && head[1].contains("--set run.frames=5"),
        "{text}"
    );
    ok(bin().args(["run", out.join("model.toml").to_str().unwrap(), "--json"]));

    // Without SOURCE_DATE_EPOCH the date is now (this year or later).
    let json = ok(bin().env_remove("SOURCE_DATE_EPOCH").args(["run", &m, "--json"]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let year: i32 = v["provenance"]["date"].as_str().unwrap()[..4].parse().unwrap();
    assert!(year >= 2026, "{v}");

    // An experiment's report ends with the section.
    let exp = d.path().join("e.toml");
    std::fs::write(
        &exp,
        format!(
            "name = \"p\"\nmodel = {m:?}\nreplications = 2\n[set]\n\"run.frames\" = 10\n\
             [[metric]]\npath = \"metrics.frame_time_ms.mean\"\n"
        ),
    )
    .unwrap();
    let eout = d.path().join("eout");
    ok(experiment(&exp, &eout).env("SOURCE_DATE_EPOCH", "0"));
    let report = std::fs::read_to_string(eout.join("report.md")).unwrap();
    let section = &report[report.find("## Provenance\n").expect(&report)..];
    assert!(section.contains("- date: 1970-01-01T00:00:00Z"), "{section}");
    assert!(
        section.contains("experiment") && section.contains("--quiet"),
        "{section}"
    );

    // A replay's JSON and model files.
    let capture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/presentmon/test_case_0.csv");
    let rout = d.path().join("rout");
    ok(bin().env("SOURCE_DATE_EPOCH", "0").args([
        "replay",
        capture.to_str().unwrap(),
        "--out",
        rout.to_str().unwrap(),
    ]));
    let replay: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rout.join("replay.json")).unwrap()).unwrap();
    assert_eq!(replay["provenance"]["date"], "1970-01-01T00:00:00Z");
    assert_eq!(replay["provenance"]["command"][1], "replay");
    assert!(
        std::fs::read_to_string(rout.join("model.toml"))
            .unwrap()
            .starts_with("# Written by rendersim ")
    );
}

#[test]
fn no_command_writes_inside_another_command_s_result_set() {
    // Issue 60 item 2: any output path inside a folder holding a set's
    // marker is refused (exit 2, naming the set and its kind) before any
    // work, whatever command writes it; the set stays byte for byte. A
    // command's own --out still takes a trace inside it.
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let set = d.path().join("set");
    ok(bin().args(["run", &m, "--out", set.to_str().unwrap()]));
    let before = snapshot(&set);
    let inside = |name: &str| set.join(name).display().to_string();
    let capture = repo_file("tests/fixtures/presentmon/test_case_0.csv");
    for args in [
        vec!["run", &m, "--trace", &inside("summary.json")],
        vec!["run", &m, "--trace", &inside("new-trace.json")],
        vec!["run", &m, "--out", &inside("nested")],
        vec!["timeline", &m, "--frames", "3", "--out", &inside("t.svg")],
        vec!["replay", &capture, "--report", &inside("report")],
        vec!["replay", &capture, "--out", &inside("replayed")],
    ] {
        let e = err(bin().args(&args));
        assert!(
            e.contains("is inside") && e.contains("a result set of `rendersim run`"),
            "{args:?}: {e}"
        );
        assert_eq!(snapshot(&set), before, "{args:?} changed the set");
    }
    ok(bin().args([
        "run",
        &m,
        "--out",
        set.to_str().unwrap(),
        "--trace",
        &inside("trace.json"),
    ]));
    assert!(set.join("trace.json").is_file());
}

/// A file of the repository, as a path string.
fn repo_file(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel).display().to_string()
}

/// Every file under `dir` (relative name, bytes), sorted.
fn tree_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn result_sets_of_one_command_compare_byte_for_byte_under_source_date_epoch_or_no_timing() {
    // Issue 60 item 11: a run's, an experiment's and a replay's folders,
    // written twice by the same command, are the same bytes when wall
    // times are fixed (SOURCE_DATE_EPOCH, or --no-timing, which also dates
    // the provenance 1970-01-01); the wall times are written as 0.
    let d = tempfile::tempdir().unwrap();
    let m = model(d.path());
    let exp = d.path().join("e.toml");
    std::fs::write(
        &exp,
        format!(
            "name = \"p\"\nmodel = {m:?}\nreplications = 2\n[set]\n\"run.frames\" = 10\n\
             [[sweep]]\nkey = \"workload.gpu\"\nvalues = [\"5ms\", \"9ms\"]\n\
             [[metric]]\npath = \"metrics.frame_time_ms.mean\"\n"
        ),
    )
    .unwrap();
    let capture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/presentmon/test_case_0.csv");
    let out = d.path().join("out");
    let commands: [Vec<&str>; 3] = [
        vec!["run", &m, "--out", out.to_str().unwrap()],
        vec![
            "experiment",
            exp.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "replay",
            capture.to_str().unwrap(),
            "--set",
            "cpu.max_frames_ahead=1",
            "--out",
            out.to_str().unwrap(),
        ],
    ];
    for fixed in [&["--no-timing"][..], &[][..]] {
        for args in &commands {
            let once = || {
                let mut c = bin();
                c.args(fixed).args(args).arg("--force");
                if fixed.is_empty() {
                    c.env("SOURCE_DATE_EPOCH", "1796386922");
                } else {
                    c.env_remove("SOURCE_DATE_EPOCH");
                }
                ok(&mut c);
                tree_bytes(&out)
            };
            let (a, b) = (once(), once());
            assert_eq!(
                a.iter().map(|f| &f.0).collect::<Vec<_>>(),
                b.iter().map(|f| &f.0).collect::<Vec<_>>()
            );
            for ((name, x), (_, y)) in a.iter().zip(&b) {
                assert!(x == y, "{fixed:?} {}: {name} differs", args[0]);
            }
            let text: String = a.iter().map(|(_, x)| String::from_utf8_lossy(x).to_string()).collect();
            if args[0] != "experiment" {
                assert!(text.contains("\"wall_seconds\": 0.0"), "{fixed:?} {}", args[0]);
            }
            let date = if fixed.is_empty() {
                "2026-12-04T"
            } else {
                "1970-01-01T00:00:00Z"
            };
            assert!(text.contains(date), "{fixed:?} {}: no {date}", args[0]);
        }
    }
}
