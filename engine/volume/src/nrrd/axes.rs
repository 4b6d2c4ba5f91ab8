//! Which axes of a NRRD file are space, channels and time (`kinds`, or the rule for
//! files without them), and the gathering of one channel's voxels from a span of the
//! data read at the axes' strides.

use std::collections::HashMap;
use std::path::Path;

use super::parse_directions;
use crate::VolumeError;

/// What each axis of the data is.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Axes {
    /// The axes that become x, y, z, in order.
    pub spatial: Vec<usize>,
    pub channel: Option<usize>,
    pub time: Option<usize>,
}

/// `kinds` that hold the components of a value at one place: channels.
const CHANNEL_KINDS: &[&str] = &[
    "list",
    "point",
    "vector",
    "covariant-vector",
    "normal",
    "stub",
    "scalar",
    "complex",
    "2-vector",
    "3-color",
    "rgb-color",
    "hsv-color",
    "xyz-color",
    "4-color",
    "rgba-color",
    "3-vector",
    "3-gradient",
    "3-normal",
    "4-vector",
    "quaternion",
];

/// Which axes are space, channels and time. By `kinds` where given (`domain`/`space`
/// are space, `time` is time, [`CHANNEL_KINDS`] are channels; `???`/`none` decide
/// nothing); otherwise for 4D data a size-1 axis is dropped, else the non-spatial axis
/// is the one whose `space directions` entry is `none` (else the last): channels when it
/// has at most 4 entries, time when more. 5D data needs `kinds`.
pub(super) fn classify_axes(
    path: &Path,
    fields: &HashMap<String, String>,
    sizes: &[i64],
) -> Result<Axes, VolumeError> {
    let n = sizes.len();
    let unsupported = |reason: String| VolumeError::Unsupported {
        path: path.to_path_buf(),
        reason,
    };
    if !(2..=5).contains(&n) {
        return Err(unsupported(format!(
            "NRRD dimension {n}: a volume needs 2 (one slice) or 3 spatial axes, with at most \
             a channel and a time axis"
        )));
    }
    let mut channel = None;
    let mut time = None;
    let mut spatial = Vec::new();
    let kinds: Option<Vec<String>> = fields
        .get("kinds")
        .map(|k| {
            k.split_whitespace()
                .map(|s| s.to_ascii_lowercase())
                .collect()
        })
        .filter(|k: &Vec<String>| k.len() == n);
    let decided = kinds
        .as_ref()
        .is_some_and(|k| k.iter().all(|k| k != "???" && k != "none"));
    if let (Some(k), true) = (&kinds, decided) {
        for (a, kind) in k.iter().enumerate() {
            let slot = if kind == "time" {
                &mut time
            } else if CHANNEL_KINDS.contains(&kind.as_str()) {
                &mut channel
            } else {
                spatial.push(a);
                continue;
            };
            if slot.replace(a).is_some() {
                return Err(VolumeError::MalformedHeader {
                    path: path.to_path_buf(),
                    field: "kinds".into(),
                    problem: format!("{k:?}: more than one {kind} axis"),
                });
            }
        }
    } else if n <= 3 {
        spatial = (0..n).collect();
    } else if n == 4 {
        let none_dir = fields
            .get("space directions")
            .and_then(|d| parse_directions(d))
            .and_then(|d| d.iter().position(Option::is_none));
        let extra = match sizes.iter().position(|&s| s == 1) {
            Some(one) => one,
            None => none_dir.unwrap_or(3),
        };
        if sizes[extra] <= 4 {
            channel = Some(extra);
        } else {
            time = Some(extra);
        }
        spatial = (0..4).filter(|&a| a != extra).collect();
    } else {
        return Err(unsupported(format!(
            "5D NRRD with sizes {sizes:?} and no `kinds`: say which axis is time and which \
             channels (e.g. `kinds: vector domain domain domain time`)"
        )));
    }
    if !(2..=3).contains(&spatial.len()) || (spatial.len() == 2 && n > 2) {
        return Err(VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: "kinds".into(),
            problem: format!(
                "{} spatial axes in sizes {sizes:?}: a volume has 3 (at most one channel and \
                 one time axis beside them)",
                spatial.len()
            ),
        });
    }
    Ok(Axes {
        spatial,
        channel,
        time,
    })
}

/// The voxels of a span read at element strides `sp` (x, y, z), packed x fastest.
pub(super) fn gather(span: Vec<u8>, b: usize, dims: [u32; 3], sp: [u64; 3]) -> Vec<u8> {
    let contiguous = sp[0] == 1
        && sp[1] == u64::from(dims[0])
        && sp[2] == u64::from(dims[0]) * u64::from(dims[1]);
    if contiguous {
        return span;
    }
    let mut out = Vec::with_capacity(crate::voxel_count(dims) as usize * b);
    for z in 0..u64::from(dims[2]) {
        for y in 0..u64::from(dims[1]) {
            for x in 0..u64::from(dims[0]) {
                let at = ((x * sp[0] + y * sp[1] + z * sp[2]) as usize) * b;
                out.extend_from_slice(&span[at..at + b]);
            }
        }
    }
    out
}
