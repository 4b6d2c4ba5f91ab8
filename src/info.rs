//! `dvr info`: what a volume file (or a list of files) holds as a series: its grid,
//! spacing, orientation, channels and time points, read as the renderer would read them
//! (`dvr_engine::volume::Series`). Reads the headers and time point 0 of each selected
//! channel (which fixes the channels' windows); no GPU. With `--labels`, the labels a
//! label map holds, named by its table.

use std::path::PathBuf;

use anyhow::{Context, Result};
use dvr_engine::volume::labels::{Label, LabelMap, LabelTable, MAX_LABEL};
use dvr_engine::volume::{Series, SeriesInfo};

/// What `dvr info` was asked.
#[derive(clap::Args)]
pub struct InfoArgs {
    /// A volume file or folder (NIfTI, NRRD, OME-Zarr, OME-TIFF, DICOM, raw with a
    /// sidecar); several files are the channels of one series (one per file, on the
    /// first file's grid), or with `--times` its time points. A name with `*` or `?`
    /// is a glob of time points.
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// The files are time points, not channels.
    #[arg(long)]
    pub times: bool,
    /// Comma-separated channel indices to read, in this order (at most 4), e.g. `0,2`.
    #[arg(long, value_delimiter = ',')]
    pub channels: Option<Vec<usize>>,
    /// Print JSON (for scripts) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Read the file as a label map (a segmentation): list the labels it holds, with
    /// their voxel counts and, from `--label-table`, names and colours.
    #[arg(long)]
    pub labels: bool,
    /// The label map's table: an ITK-SNAP label description file, or a Slicer colour
    /// table (`.ctbl`). Labels it lacks take palette colours.
    #[arg(long, requires = "labels")]
    pub label_table: Option<PathBuf>,
}

pub fn run(args: &InfoArgs) -> Result<()> {
    if args.labels {
        return labels(args);
    }
    let sel = args.channels.as_deref();
    let glob = args.paths.iter().any(|p| {
        p.file_name()
            .is_some_and(|n| n.to_string_lossy().contains(['*', '?']))
    });
    let series = if glob {
        let mut files = Vec::new();
        for p in &args.paths {
            files.extend(dvr_engine::volume::expand_glob(p)?);
        }
        Series::open_times(&files, sel)
    } else if args.paths.len() == 1 {
        Series::open(&args.paths[0], sel)
    } else if args.times {
        Series::open_times(&args.paths, sel)
    } else {
        Series::open_channels(&args.paths, sel)
    }
    .with_context(|| format!("reading {}", args.paths[0].display()))?;
    let info = series.info();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&to_json(info))?);
    } else {
        print!("{}", to_text(info));
    }
    Ok(())
}

fn colour_hex(c: Option<[u8; 3]>) -> Option<String> {
    c.map(|c| format!("{:02X}{:02X}{:02X}", c[0], c[1], c[2]))
}

fn to_json(info: &SeriesInfo) -> serde_json::Value {
    let t = &info.to_patient;
    // Row-major 4×4, as NIfTI's sform and nibabel's affine are written.
    let affine: Vec<[f64; 4]> = (0..3)
        .map(|r| [t.axes[0][r], t.axes[1][r], t.axes[2][r], t.origin[r]])
        .chain(std::iter::once([0.0, 0.0, 0.0, 1.0]))
        .collect();
    let channels: Vec<serde_json::Value> = info
        .channels
        .iter()
        .map(|c| {
            serde_json::json!({
                "name": c.name,
                "index": c.index,
                "file": c.file.display().to_string(),
                "colour": colour_hex(c.colour),
                "window": c.window,
                "display_window": c.display_window,
                "dtype": c.sample_kind.name(),
                "resampled": c.resampled,
            })
        })
        .collect();
    serde_json::json!({
        "name": info.name,
        "dims": info.dims,
        "spacing": info.spacing,
        "to_patient": affine,
        "frame": "RAS",
        "channels": channels,
        "times": info.times,
    })
}

fn to_text(info: &SeriesInfo) -> String {
    let t = &info.to_patient;
    let mut s = format!(
        "{}\n  grid        {} x {} x {} voxels (RAS order)\n  spacing     {} x {} x {} mm\n  \
         to_patient  origin ({:.3}, {:.3}, {:.3}) mm, axes R/A/S\n  time points {}\n  \
         channels    {}\n",
        info.name,
        info.dims[0],
        info.dims[1],
        info.dims[2],
        info.spacing[0],
        info.spacing[1],
        info.spacing[2],
        t.origin[0],
        t.origin[1],
        t.origin[2],
        info.times,
        info.channels.len()
    );
    for (i, c) in info.channels.iter().enumerate() {
        s += &format!(
            "    {i}: {} (index {}, {}), colour {}, window [{}, {}]{}{}\n",
            c.name,
            c.index,
            c.sample_kind.name(),
            colour_hex(c.colour).unwrap_or_else(|| "-".into()),
            c.window[0],
            c.window[1],
            c.display_window
                .map(|w| format!(", display window [{}, {}]", w[0], w[1]))
                .unwrap_or_default(),
            if c.resampled {
                ", resampled onto the first grid"
            } else {
                ""
            }
        );
    }
    s
}

/// `--labels`: the labels a label map holds, each with its voxel count and its table
/// entry (name, colour, opacity, shown).
fn labels(args: &InfoArgs) -> Result<()> {
    let path = &args.paths[0];
    let (map, own) =
        LabelMap::load_with_table(path).with_context(|| format!("reading {}", path.display()))?;
    let mut table = match &args.label_table {
        Some(t) => LabelTable::load(t).with_context(|| format!("reading {}", t.display()))?,
        None => own.unwrap_or_default(),
    };
    let present = map.present();
    let unnamed = table.complete(&present);
    if args.label_table.is_some() && !unnamed.is_empty() {
        log::warn!(
            "{}: label(s) {unnamed:?} are not in the table; they take palette colours",
            path.display()
        );
    }
    let mut counts = vec![0u64; MAX_LABEL as usize + 1];
    for &v in &map.values {
        counts[usize::from(v)] += 1;
    }
    let rows: Vec<(u16, &Label, u64)> = present
        .iter()
        .filter_map(|&v| table.get(v).map(|l| (v, l, counts[usize::from(v)])))
        .collect();
    let hex = |c: [f32; 3]| {
        let b = c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
        format!("{:02X}{:02X}{:02X}", b[0], b[1], b[2])
    };
    if args.json {
        let labels: Vec<serde_json::Value> = rows
            .iter()
            .map(|(v, l, n)| {
                serde_json::json!({"value": v, "name": l.name, "colour": hex(l.colour),
                    "opacity": l.opacity, "visible": l.visible, "voxels": n})
            })
            .collect();
        let out = serde_json::json!({"name": map.name, "dims": map.dims, "labels": labels});
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let [x, y, z] = map.dims;
        println!(
            "{}\n  grid    {x} x {y} x {z} voxels (RAS order)\n  labels  {}",
            map.name,
            rows.len()
        );
        for (v, l, n) in rows {
            println!(
                "    {v}: {} (colour {}, opacity {}, {}), {n} voxels",
                l.name,
                hex(l.colour),
                l.opacity,
                if l.visible { "shown" } else { "hidden" }
            );
        }
    }
    Ok(())
}
