//! The built `dvr` binary as the command-line tests run it: with the validation layer
//! on, its output and the checks of a clean exit or a clean error.

use std::process::{Command, Output};

pub fn dvr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(args)
        .env("DVR_VALIDATION", "1")
        .output()
        .expect("run dvr")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn assert_ok(o: &Output) {
    assert!(
        o.status.success(),
        "dvr failed ({:?}):\n{}",
        o.status.code(),
        stderr(o)
    );
}

/// Fails with exit status 1 and a message containing every one of `needles`.
pub fn assert_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(
        o.status.code(),
        Some(1),
        "expected a clean error exit, got:\n{err}"
    );
    assert!(!err.contains("panicked"), "panicked:\n{err}");
    for n in needles {
        assert!(err.contains(n), "message should mention {n:?}:\n{err}");
    }
}
