//! Named presets: `assets/transfer/<name>.toml`, one file per TF.
//!
//! Presets are files, not code, so they can be tuned without a rebuild and a user can
//! copy one as a starting point. Where the folder is: [`dvr_volume::assets`].

use super::{TransferError, TransferFunction};

impl TransferFunction {
    /// Loads the preset `name` (`assets/transfer/<name>.toml`). An unknown name lists
    /// the available ones.
    pub fn preset(name: &str) -> Result<Self, TransferError> {
        let dir = dvr_volume::assets::transfer_presets();
        let plain = !name.is_empty() && !name.contains(['/', '\\']) && name != "." && name != "..";
        let path = dir.join(format!("{name}.toml"));
        if !plain || !path.is_file() {
            let available = match Self::preset_names() {
                Ok(names) if !names.is_empty() => names.join(", "),
                Ok(_) => "none".to_string(),
                Err(e) => format!("none ({e})"),
            };
            return Err(TransferError::UnknownPreset {
                name: name.to_string(),
                dir,
                available,
            });
        }
        Self::load(path)
    }

    /// The names of all presets (file stems in `assets/transfer/`), sorted.
    pub fn preset_names() -> Result<Vec<String>, TransferError> {
        let dir = dvr_volume::assets::transfer_presets();
        let io = |source| TransferError::Io {
            path: dir.clone(),
            source,
        };
        let mut names = Vec::new();
        for entry in std::fs::read_dir(&dir).map_err(io)? {
            let path = entry.map_err(io)?.path();
            if path.extension().is_some_and(|e| e == "toml") {
                if let Some(stem) = path.file_stem() {
                    names.push(stem.to_string_lossy().into_owned());
                }
            }
        }
        names.sort();
        Ok(names)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::LUT_SIZE;

    /// The presets the built-in scenes and the docs rely on.
    const REQUIRED: [&str; 15] = [
        "phantom-opaque",
        "phantom-opaque-edit",
        "phantom-layered",
        "phantom-layered-edit",
        "mri-opaque",
        "mri-opaque-edit",
        "mri-layered",
        "mri-layered-edit",
        "cloud",
        "cloud-edit",
        "ct-bone",
        "ct-soft-tissue",
        "ct-angio",
        "ct-lung",
        "ct-skin",
    ];

    /// A 12-bit CT's Hounsfield range: where the data-unit presets are looked at.
    const CT_WINDOW: [f32; 2] = [-1024.0, 3071.0];
    /// A z map's range: where the statistical-map presets are looked at.
    const Z_WINDOW: [f32; 2] = [-10.0, 10.0];

    #[test]
    fn all_presets_load_and_are_valid() {
        let names = TransferFunction::preset_names().expect("preset folder readable");
        for r in REQUIRED {
            assert!(
                names.iter().any(|n| n == r),
                "missing preset {r}; have {names:?}"
            );
        }
        for name in &names {
            let tf = TransferFunction::preset(name).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(&tf.name, name, "preset name must match its file");
            tf.validate().unwrap_or_else(|e| panic!("{e}"));
            if tf.units == crate::transfer::TfUnits::Data && !name.starts_with("ct-") {
                // A statistical map's preset: z = 0 (no effect) is clear, and it shows
                // something over a z range.
                let lut = tf.in_density(Z_WINDOW).lut();
                assert!(lut.max_opacity() > 0.0, "{name} is invisible");
                assert_eq!(tf.sample(0.0).opacity, 0.0, "{name}: z = 0 must be clear");
                continue;
            }
            let lut = tf.in_density(CT_WINDOW).lut();
            assert_eq!(lut.len(), LUT_SIZE);
            assert!(lut.max_opacity() > 0.0, "{name} is invisible");
            // Air (density 0) is transparent in every preset.
            assert_eq!(lut.diffuse_opacity[0][3], 0.0, "{name}: air must be clear");
        }
    }

    #[test]
    fn edits_differ_from_their_originals() {
        for r in REQUIRED.iter().filter(|r| r.ends_with("-edit")) {
            let base = r.trim_end_matches("-edit");
            let a = TransferFunction::preset(base).expect("base preset");
            let b = TransferFunction::preset(r).expect("edit preset");
            let (a, b) = (a.in_density(CT_WINDOW).lut(), b.in_density(CT_WINDOW).lut());
            assert!(a.max_abs_diff(&b) > 0.1, "{r} barely changes {base}");
        }
    }

    #[test]
    fn unknown_preset_lists_the_available_ones() {
        let e = TransferFunction::preset("no-such-preset")
            .map(|_| ())
            .map_err(|e| e.to_string());
        assert!(
            matches!(&e, Err(m) if m.contains("no-such-preset") && m.contains("phantom-opaque")),
            "{e:?}"
        );
        assert!(TransferFunction::preset("../transfer/cloud").is_err());
        assert!(TransferFunction::preset("").is_err());
    }
}
