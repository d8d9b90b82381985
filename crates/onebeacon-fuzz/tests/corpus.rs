//! Every checked-in fuzz input, on the stable toolchain: the seeds each target starts
//! from (`fuzz/seeds/TARGET/`) and whatever the fuzzers found
//! (`fuzz/regressions/TARGET/`, one file per input that once crashed or failed a check).

use std::path::PathBuf;

#[test]
fn every_checked_in_input_passes_its_target() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut counts = Vec::new();
    for (target, run) in onebeacon_fuzz::TARGETS {
        let mut n = 0;
        for kind in ["seeds", "regressions"] {
            let Ok(dir) = std::fs::read_dir(root.join(kind).join(target)) else { continue };
            let mut files: Vec<PathBuf> = dir.map(|e| e.unwrap().path()).collect();
            files.sort();
            for f in files {
                let data = std::fs::read(&f).unwrap();
                let outcome = std::panic::catch_unwind(|| run(&data));
                assert!(outcome.is_ok(), "{target}: {} fails", f.display());
                n += 1;
            }
        }
        counts.push((target, n));
    }
    // every target has seeds: an empty or misplaced corpus must not pass unseen
    for (target, n) in counts {
        assert!(n > 0, "no input for target {target} under fuzz/seeds or fuzz/regressions");
    }
}
