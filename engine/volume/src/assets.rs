//! Where the files dvr ships live: `$DVR_ASSETS` when set and non-empty, else the folder
//! an application set with [`set_assets_dir`] (the Python wheel's packaged copy), else
//! `assets/` in the workspace this crate was built from. Every loader of a shipped file
//! (the MRI volume, TF presets, RAE networks) finds it through here.

use std::path::{Path, PathBuf};
use std::sync::RwLock;

/// The folder an application ships its own copy of the assets in (set once at start).
static SET_DIR: RwLock<Option<PathBuf>> = RwLock::new(None);

/// Makes `dir` the assets folder when `$DVR_ASSETS` is not set: an installed package
/// carries its assets with it, so it must not depend on the checkout it was built from
/// (which may be gone). `$DVR_ASSETS` still wins, so a user can point at other files.
pub fn set_assets_dir(dir: impl Into<PathBuf>) {
    // A poisoned lock only means a writer panicked; the value is a plain path.
    *SET_DIR.write().unwrap_or_else(|e| e.into_inner()) = Some(dir.into());
}

/// The environment variable that moves the assets folder (an installed binary, a GPU
/// machine with the assets copied elsewhere).
pub const ASSETS_ENV: &str = "DVR_ASSETS";

/// The assets folder.
pub fn assets_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os(ASSETS_ENV).filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    if let Some(dir) = SET_DIR.read().unwrap_or_else(|e| e.into_inner()).clone() {
        return dir;
    }
    // This crate is `engine/volume/` of the workspace.
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

/// The MNI152 T1 template behind the `mri` dataset.
pub fn mri_volume() -> PathBuf {
    assets_dir().join("volumes/mni152_t1.nii.gz")
}

/// The segmentation of the MNI152 head (white matter, grey matter, the rest) and its ITK-SNAP
/// label file: the `mri` dataset's built-in labels.
pub fn mri_labels() -> (PathBuf, PathBuf) {
    let dir = assets_dir().join("volumes");
    (
        dir.join("mni152_labels.nii.gz"),
        dir.join("mni152_labels.label"),
    )
}

/// The folder of transfer-function presets (`<name>.toml`).
pub fn transfer_presets() -> PathBuf {
    assets_dir().join("transfer")
}

/// The manifest of the shipped RAE network `net` (`<net>.json`, naming its weights).
pub fn rae_manifest(net: &str) -> PathBuf {
    assets_dir().join("rae").join(format!("{net}.json"))
}

/// The manifest of ours' shipped young-pixel network (`young/young.json`, naming its
/// weights).
pub fn young_manifest() -> PathBuf {
    assets_dir().join("young").join("young.json")
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
