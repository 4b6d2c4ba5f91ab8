#![no_main]
//! Fuzz target: see `dvr_fuzz::tf_toml`.

use std::path::PathBuf;
use std::sync::OnceLock;

static SCRATCH: OnceLock<PathBuf> = OnceLock::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    dvr_fuzz::tf_toml(data, SCRATCH.get_or_init(dvr_fuzz::process_scratch));
});
