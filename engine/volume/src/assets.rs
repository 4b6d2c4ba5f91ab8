//! Where the files dvr ships live: `$DVR_ASSETS` when set and non-empty, else `assets/`
//! in the workspace this crate was built from. Every loader of a shipped file (the MRI
//! volume, TF presets, RAE networks) finds it through here.

use std::path::{Path, PathBuf};

/// The environment variable that moves the assets folder (an installed binary, a GPU
/// machine with the assets copied elsewhere).
pub const ASSETS_ENV: &str = "DVR_ASSETS";

/// The assets folder.
pub fn assets_dir() -> PathBuf {
    match std::env::var_os(ASSETS_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        // This crate is `engine/volume/` of the workspace.
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets"),
    }
}

/// The MNI152 T1 template behind the `mri` dataset.
pub fn mri_volume() -> PathBuf {
    assets_dir().join("volumes/mni152_t1.nii.gz")
}

/// The folder of transfer-function presets (`<name>.toml`).
pub fn transfer_presets() -> PathBuf {
    assets_dir().join("transfer")
}

/// The manifest of the shipped RAE network `net` (`<net>.json`, naming its weights).
pub fn rae_manifest(net: &str) -> PathBuf {
    assets_dir().join("rae").join(format!("{net}.json"))
}

/// The folder of a shipped scene set (`assets/scenes/<set>/`, one scene file each):
/// `validation`, `static` and `paper`, the sets `dvr eval --scene <set>` runs.
pub fn scene_set(set: &str) -> PathBuf {
    assets_dir().join("scenes").join(set)
}

/// The folder of the shipped RAE networks.
pub fn rae_dir() -> PathBuf {
    assets_dir().join("rae")
}
