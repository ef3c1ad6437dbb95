//! Records the git revision the binary is built from (for the provenance
//! written beside every result; `None` outside a git checkout or without
//! git). `-dirty` is appended when tracked files differ from that revision.

use std::process::Command;

fn git(args: &[&str]) -> Option<std::process::Output> {
    Command::new("git").args(args).output().ok()
}

fn main() {
    // Rerun when the checked-out revision or the sources change (a change
    // to the sources can make the tree dirty or clean again).
    for path in [".git/HEAD", ".git/index", ".git/refs", "src", "crates", "Cargo.toml"] {
        println!("cargo:rerun-if-changed={path}");
    }
    let revision = git(&["rev-parse", "--short=12", "HEAD"])
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty());
    let Some(mut revision) = revision else {
        return;
    };
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
        .filter(|o| o.status.success())
        .is_some_and(|o| !o.stdout.is_empty());
    if dirty {
        revision.push_str("-dirty");
    }
    println!("cargo:rustc-env=RENDERSIM_GIT_REVISION={revision}");
}
