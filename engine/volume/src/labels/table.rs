//! Label tables: per label value a name, a colour, an opacity and whether it is shown,
//! read from the files segmentation tools write: ITK-SNAP's label description file
//! (`IDX R G B A VIS MSH "LABEL"`, colours 0–255, opacity 0–1) and 3D Slicer's colour
//! table (`.ctbl`: `value name R G B A`, all 0–255). Labels a map holds that a table
//! does not name take a colour from a fixed palette.

use crate::VolumeError;
use std::path::Path;

/// One label of a table.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub value: u16,
    pub name: String,
    /// RGB in [0, 1].
    pub colour: [f32; 3],
    /// In [0, 1]: scales the label's opacity.
    pub opacity: f32,
    pub visible: bool,
}

/// Labels by value, ascending, each value once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelTable {
    pub labels: Vec<Label>,
}

/// The colours unnamed labels take, by value (cycled): distinct, mid-bright hues.
pub const PALETTE: [[f32; 3]; 12] = [
    [0.90, 0.30, 0.25],
    [0.30, 0.65, 0.90],
    [0.40, 0.80, 0.35],
    [0.95, 0.70, 0.20],
    [0.65, 0.45, 0.85],
    [0.25, 0.80, 0.75],
    [0.95, 0.50, 0.70],
    [0.70, 0.75, 0.30],
    [0.55, 0.55, 0.95],
    [0.85, 0.55, 0.35],
    [0.45, 0.85, 0.55],
    [0.80, 0.35, 0.55],
];

impl LabelTable {
    /// Reads a table file: `.ctbl` is a Slicer colour table, anything else an ITK-SNAP
    /// label description file.
    pub fn load(path: &Path) -> Result<Self, VolumeError> {
        let text =
            crate::files::read_text(path, crate::files::MAX_TEXT_FILE_BYTES).map_err(|e| {
                VolumeError::MalformedHeader {
                    path: path.to_path_buf(),
                    field: "label table".into(),
                    problem: e.to_string(),
                }
            })?;
        let slicer = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ctbl"));
        if slicer {
            Self::parse_slicer(&text, path)
        } else {
            Self::parse_itksnap(&text, path)
        }
    }

    /// ITK-SNAP: `IDX -R- -G- -B- -A-- VIS MSH "LABEL"` per line, `#` comments.
    pub fn parse_itksnap(text: &str, origin: &Path) -> Result<Self, VolumeError> {
        let mut labels = Vec::new();
        for (n, line) in data_lines(text) {
            let err = |problem: String| line_error(origin, n, problem);
            let (numbers, name) = match line.find('"') {
                Some(q) => {
                    let rest = &line[q + 1..];
                    let end = rest
                        .rfind('"')
                        .ok_or_else(|| err("the label's name has no closing quote".into()))?;
                    (&line[..q], rest[..end].to_string())
                }
                None => return Err(err("expected IDX R G B A VIS MSH \"LABEL\"".into())),
            };
            let f: Vec<&str> = numbers.split_whitespace().collect();
            if f.len() != 7 {
                return Err(err(format!(
                    "{} numbers before the name; expected 7 (IDX R G B A VIS MSH)",
                    f.len()
                )));
            }
            let value = parse_value(f[0]).map_err(err)?;
            let colour = rgb255(&f[1..4]).map_err(err)?;
            let opacity = parse_unit(f[4], "A (opacity)").map_err(err)?;
            let visible = match f[5] {
                "0" => false,
                "1" => true,
                v => return Err(err(format!("VIS {v:?} must be 0 or 1"))),
            };
            labels.push(Label {
                value,
                name,
                colour,
                opacity,
                visible,
            });
        }
        Self::checked(labels, origin)
    }

    /// 3D Slicer: `value name R G B A` per line (0–255 each), `#` comments.
    pub fn parse_slicer(text: &str, origin: &Path) -> Result<Self, VolumeError> {
        let mut labels = Vec::new();
        for (n, line) in data_lines(text) {
            let err = |problem: String| line_error(origin, n, problem);
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() != 6 {
                return Err(err(format!(
                    "{} fields; expected 6 (value name R G B A)",
                    f.len()
                )));
            }
            let value = parse_value(f[0]).map_err(err)?;
            let colour = rgb255(&f[2..5]).map_err(err)?;
            let a = parse_255(f[5], "A").map_err(err)?;
            labels.push(Label {
                value,
                name: f[1].to_string(),
                colour,
                opacity: a,
                visible: true,
            });
        }
        Self::checked(labels, origin)
    }

    fn checked(mut labels: Vec<Label>, origin: &Path) -> Result<Self, VolumeError> {
        labels.sort_by_key(|l| l.value);
        if let Some(w) = labels.windows(2).find(|w| w[0].value == w[1].value) {
            return Err(VolumeError::MalformedHeader {
                path: origin.to_path_buf(),
                field: "label table".into(),
                problem: format!("label {} is given twice", w[0].value),
            });
        }
        Ok(Self { labels })
    }

    pub fn get(&self, value: u16) -> Option<&Label> {
        self.labels
            .binary_search_by_key(&value, |l| l.value)
            .ok()
            .map(|i| &self.labels[i])
    }

    /// Adds every value of `present` the table lacks (named `label <v>`, a palette
    /// colour, opaque and shown); returns the values added, for one warning that lists
    /// them.
    pub fn complete(&mut self, present: &[u16]) -> Vec<u16> {
        let missing: Vec<u16> = present
            .iter()
            .copied()
            .filter(|&v| v != 0 && self.get(v).is_none())
            .collect();
        for &v in &missing {
            self.labels.push(Label {
                value: v,
                name: format!("label {v}"),
                colour: PALETTE[usize::from(v) % PALETTE.len()],
                opacity: 1.0,
                visible: true,
            });
        }
        self.labels.sort_by_key(|l| l.value);
        missing
    }
}

/// Non-empty, non-comment lines with their 1-based numbers.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

fn line_error(origin: &Path, n: usize, problem: String) -> VolumeError {
    VolumeError::MalformedHeader {
        path: origin.to_path_buf(),
        field: format!("line {n}"),
        problem,
    }
}

fn parse_value(s: &str) -> Result<u16, String> {
    s.parse::<u16>()
        .map_err(|_| format!("label value {s:?} must be an integer 0 to {}", u16::MAX))
}

fn parse_255(s: &str, what: &str) -> Result<f32, String> {
    match s.parse::<u16>() {
        Ok(v) if v <= 255 => Ok(f32::from(v) / 255.0),
        _ => Err(format!("{what} {s:?} must be an integer 0 to 255")),
    }
}

fn rgb255(f: &[&str]) -> Result<[f32; 3], String> {
    Ok([
        parse_255(f[0], "R")?,
        parse_255(f[1], "G")?,
        parse_255(f[2], "B")?,
    ])
}

fn parse_unit(s: &str, what: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("{what} {s:?} must be a number 0 to 1")),
    }
}
