//! The font the charts and the videos' labels are drawn with: `ab_glyph` reads a
//! TrueType file at run time ([`init_font`]), so building needs no fontconfig/freetype;
//! `tools/setup.sh` installs `fonts-dejavu-core`, and `DVR_FONT` can name any other font
//! file.

use anyhow::{bail, Result};
use plotters::style::FontStyle;
use std::path::PathBuf;
use std::sync::OnceLock;

/// Font files tried in order after `DVR_FONT` (Debian/Ubuntu, Fedora, Arch, macOS,
/// Windows).
const FONT_CANDIDATES: [&str; 7] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/noto/NotoSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

static FONT: OnceLock<std::result::Result<PathBuf, String>> = OnceLock::new();

/// Registers the plots' font once per process; fails with what to install when there
/// is none.
pub fn init_font() -> Result<()> {
    let r = FONT.get_or_init(|| {
        let chosen = std::env::var_os("DVR_FONT").map(PathBuf::from);
        if let Some(path) = &chosen {
            // A named font that does not load is worth a warning; the usual places
            // are tried next.
            match load_font(path) {
                Ok(()) => return Ok(path.clone()),
                Err(why) => {
                    log::warn!("DVR_FONT={}: {why}; trying the usual fonts", path.display())
                }
            }
        }
        for path in FONT_CANDIDATES.iter().map(PathBuf::from) {
            if load_font(&path).is_ok() {
                return Ok(path);
            }
        }
        Err(
            "no TrueType font found for the plots: install fonts-dejavu-core \
             (tools/setup.sh does) or set DVR_FONT=/path/to/font.ttf"
                .to_string(),
        )
    });
    match r {
        Ok(_) => Ok(()),
        Err(e) => bail!("{e}"),
    }
}

/// Largest font file read: real TrueType/OpenType fonts are well under this (DejaVu
/// Sans is 0.7 MB; the largest CJK fonts about 20 MB).
const MAX_FONT_BYTES: u64 = 64 << 20;

/// Reads and registers one font file for every family the plots use; says why not.
fn load_font(path: &std::path::Path) -> std::result::Result<(), String> {
    let bytes = dvr_engine::files::read_bounded(path, MAX_FONT_BYTES).map_err(|e| e.to_string())?;
    // Parsed first, so a file that is not a font is told apart from one that is.
    ab_glyph::FontRef::try_from_slice(&bytes)
        .map_err(|_| "is not a TrueType or OpenType font".to_string())?;
    // plotters keeps fonts for the life of the process.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    ["sans-serif", "serif", "monospace"]
        .iter()
        .try_for_each(|family| {
            plotters::style::register_font(family, FontStyle::Normal, bytes)
                .map_err(|_| "is not a font the plots can use".to_string())
        })
}
