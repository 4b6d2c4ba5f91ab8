#![no_main]
//! Fuzz target: see `dvr_fuzz::label_table`.

use std::path::PathBuf;
use std::sync::OnceLock;

static SCRATCH: OnceLock<PathBuf> = OnceLock::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    dvr_fuzz::label_table(data, SCRATCH.get_or_init(dvr_fuzz::process_scratch));
});
