//! Which scenes an eval runs, the folder each one's files go to, and where a scene's
//! sudden change happens.

use anyhow::{bail, Context, Result};
use dvr_engine::renderer::FrameInputs;
use dvr_engine::scene::Scene;

/// Animations that make methods fail on purpose; `--scene stress` runs these and
/// `--scene suite` leaves them out.
pub const STRESS_ANIMATIONS: [&str; 3] = ["tf-jump", "light-jump", "fast-orbit"];

/// Scene sets shipped as folders of scene files (`assets/scenes/<set>/*.toml`): the
/// frozen validation set (48 frames of continuous change each, never tuned on), the
/// development scenes beside the suite (kinds of change the built-ins lack, tuned on
/// with it), the static views, and `paper`, the TVCG paper's conditions (ray marching,
/// single scattering with the hybrid phase, emission, one animation type per scene), and
/// the frozen interaction set (drags at the speeds people drag, let go, and cold opens).
pub const FILE_SETS: [&str; 5] = [
    "validation",
    "development",
    "static",
    "paper",
    "interaction",
];

/// The scene files of a shipped set, sorted by file name.
fn set_files(set: &str) -> Result<Vec<String>> {
    let dir = dvr_engine::assets::scene_set(set);
    let entries = std::fs::read_dir(&dir)
        .with_context(|| format!("reading the scene set {set:?} in {}", dir.display()))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry
            .with_context(|| format!("reading {}", dir.display()))?
            .path();
        if path.extension().is_some_and(|e| e == "toml") {
            files.push(path.to_string_lossy().into_owned());
        }
    }
    files.sort();
    if files.is_empty() {
        bail!(
            "the scene set {set:?} has no scene files in {}",
            dir.display()
        );
    }
    Ok(files)
}

/// Animations with one sudden change, after which frames to recover are measured.
pub const SUDDEN_ANIMATIONS: [&str; 2] = ["tf-jump", "light-jump"];

fn animation(name: &str) -> &str {
    name.rsplit('/').next().unwrap_or(name)
}

/// The scene names (or files) `--scene` selects, in order, without duplicates.
pub fn select(spec: &str) -> Result<Vec<String>> {
    let builtin = Scene::builtin_names();
    let is_stress = |n: &String| STRESS_ANIMATIONS.contains(&animation(n));
    let mut out: Vec<String> = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let add: Vec<String> = match item {
            "suite" => builtin.iter().filter(|n| !is_stress(n)).cloned().collect(),
            "stress" => builtin.iter().filter(|n| is_stress(n)).cloned().collect(),
            set if FILE_SETS.contains(&set) => set_files(set)?,
            other => vec![other.to_string()],
        };
        for n in add {
            if !out.contains(&n) {
                out.push(n);
            }
        }
    }
    if out.is_empty() {
        bail!("--scene selects no scene (use suite, stress, or names from `dvr scenes`)");
    }
    Ok(out)
}

/// The folder name of a scene inside the eval folder: its name with `/` (and anything
/// else that is awkward in a path or URL) replaced by `_`, e.g. `cloud/orbit` →
/// `cloud_orbit`.
pub fn dir_name(scene: &str) -> String {
    let s: String = scene
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let s = s.trim_matches('.').to_string();
    if s.is_empty() {
        "scene".to_string()
    } else {
        s
    }
}

/// Makes `labels` (the scenes' names, in order) unique, and gives each a folder name
/// inside the eval folder that is unique too: a repeated label gets `-2`, `-3`, … (two
/// scene files both named `head` become `head` and `head-2`), and a folder that another
/// label already sanitised to (`a/b` and `a_b` both give `a_b`) gets the same suffix.
/// Returns (label, folder) per scene.
pub fn unique_labels(labels: &[String]) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for label in labels {
        let taken = |l: &str, d: &str| out.iter().any(|(ol, od)| ol == l || od == d);
        let mut unique = (label.clone(), dir_name(label));
        let mut n = 2;
        while taken(&unique.0, &unique.1) {
            unique = (format!("{label}-{n}"), format!("{}-{n}", dir_name(label)));
            n += 1;
        }
        out.push(unique);
    }
    out
}

/// True for scenes with one sudden change (a TF or light jump).
pub fn has_sudden_change(scene: &str) -> bool {
    SUDDEN_ANIMATIONS.contains(&animation(scene))
}

/// The frame at which a sudden change takes effect: the first frame whose lights or
/// transfer function differ from the frame before (the built-in jumps happen at the
/// middle frame; this finds it whatever `--frames` rescaled it to). Falls back to the
/// middle frame when nothing changes.
pub fn event_frame(frames: u32, inputs: impl Fn(u32) -> FrameInputs) -> u32 {
    let mut prev = inputs(0);
    for f in 1..frames {
        let cur = inputs(f);
        if cur.lights != prev.lights || cur.lut != prev.lut {
            return f;
        }
        prev = cur;
    }
    frames / 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suite_and_stress_split_the_builtins() {
        let all = Scene::builtin_names();
        let suite = select("suite").unwrap();
        let stress = select("stress").unwrap();
        assert_eq!(suite.len() + stress.len(), all.len());
        assert!(stress
            .iter()
            .all(|n| STRESS_ANIMATIONS.contains(&animation(n))));
        assert!(suite
            .iter()
            .all(|n| !STRESS_ANIMATIONS.contains(&animation(n))));
        assert!(stress.contains(&"cloud/tf-jump".to_string()));
        assert!(suite.contains(&"cloud/orbit".to_string()));
    }

    #[test]
    fn the_file_sets_are_scene_files_that_load() {
        // Per shipped set: the prefix its scenes' names carry and its least size.
        let sets = [
            ("validation", "val/", 8),
            ("development", "dev/", 1),
            ("static", "static/", 2),
            ("paper", "paper/", 5),
            ("interaction", "int/", 7),
        ];
        assert_eq!(sets.map(|(set, _, _)| set), FILE_SETS);
        for (set, prefix, least) in sets {
            let files = select(set).unwrap();
            assert!(files.len() >= least, "{set}: {files:?}");
            for file in &files {
                let scene = Scene::load(file).unwrap_or_else(|e| panic!("{file}: {e}"));
                assert!(
                    scene.name.starts_with(prefix),
                    "{file}: named {:?}",
                    scene.name
                );
                assert!(scene.frames >= 48, "{file}: {} frames", scene.frames);
            }
        }
        // Selected twice (or beside one of its files), each file runs once.
        let both = select("validation,validation").unwrap();
        assert_eq!(both, select("validation").unwrap());
    }

    #[test]
    fn lists_keep_order_and_drop_duplicates() {
        let s = select("cloud/orbit, phantom/tf-jump,cloud/orbit").unwrap();
        assert_eq!(s, vec!["cloud/orbit", "phantom/tf-jump"]);
        assert!(select(" , ").is_err());
    }

    #[test]
    fn folder_names() {
        assert_eq!(dir_name("cloud/orbit"), "cloud_orbit");
        assert_eq!(dir_name("mri/tf-jump"), "mri_tf-jump");
        assert_eq!(dir_name("../x y"), "_x_y");
        assert_eq!(dir_name(".."), "scene");
    }

    #[test]
    fn labels_and_folders_are_unique() {
        let l = |v: &[&str]| unique_labels(&v.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(
            l(&["cloud/orbit", "head"]),
            vec![
                ("cloud/orbit".to_string(), "cloud_orbit".to_string()),
                ("head".to_string(), "head".to_string())
            ]
        );
        let twice = l(&["head", "head", "head"]);
        assert_eq!(twice[1], ("head-2".to_string(), "head-2".to_string()));
        assert_eq!(twice[2], ("head-3".to_string(), "head-3".to_string()));
        // Different labels, one sanitised folder name.
        let clash = l(&["a/scene", "a_scene"]);
        assert_eq!(clash[0].1, "a_scene");
        assert_eq!(clash[1], ("a_scene-2".to_string(), "a_scene-2".to_string()));
    }

    #[test]
    fn sudden_changes() {
        assert!(has_sudden_change("mri/tf-jump"));
        assert!(has_sudden_change("cloud/light-jump"));
        assert!(!has_sudden_change("cloud/fast-orbit"));
        assert!(!has_sudden_change("cloud/orbit"));
    }
}
