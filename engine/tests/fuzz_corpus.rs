//! Replays every committed fuzz corpus file (`fuzz/corpus/<target>/`: the seeds, and
//! each input that once crashed a loader) through the fuzz targets' own entry points,
//! so a plain `cargo test` (CI, no nightly) keeps every loader of untrusted input
//! panic-free on them. Fuzzing itself: README "Reliability".

// `process_scratch` is for the fuzz targets only.
#[allow(dead_code)]
#[path = "../../fuzz/src/entries.rs"]
mod entries;

use std::path::Path;

#[test]
fn every_corpus_file_loads_or_fails_cleanly() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    let scratch = tempfile::tempdir().expect("scratch folder");
    for (target, entry) in entries::TARGETS {
        let dir = corpus.join(target);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.expect("corpus entry").path())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{} has no seeds", dir.display());
        for file in files {
            let bytes = std::fs::read(&file).expect("corpus file");
            // A panic here names the target and the file that caused it.
            let result = std::panic::catch_unwind(|| entry(&bytes, scratch.path()));
            assert!(result.is_ok(), "{target} panicked on {}", file.display());
        }
    }
}
