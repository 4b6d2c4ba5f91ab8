//! Mouse and keyboard to camera and UI commands, and the `--script` that plays the same
//! commands at given frames (for tests and scripted demos).
//!
//! Script syntax: commands separated by `;`, each `ACTION:ARGS@FRAME`:
//!
//! | command | effect |
//! | --- | --- |
//! | `orbit:DX,DY@F` | a left-drag of (DX, DY) pixels at frame F |
//! | `pan:DX,DY@F` | a right-drag of (DX, DY) pixels |
//! | `zoom:STEPS@F` | wheel steps (positive zooms in) |
//! | `key:NAME@F` | a key: `r` (reset), `f` (fit), `c` (cuts off/on), `h` (help), `f12` (screenshot), `tab` (UI) |
//! | `denoiser:NAME@F` | show denoiser NAME |
//! | `split:NAME@F` | split view with NAME on the right (`split:off` ends it) |
//! | `tf:NAME@F` | the transfer function: a preset name, or a TF file path (as the panel's presets and load) |
//! | `size:WxH@F` | resizes the window so the view is W×H pixels |
//! | `clip:add@F` | a clip plane through the centre, facing the view (as the panel's "add plane") |
//! | `clip:offset:D@F` | moves the last plane D world units along its normal |
//! | `clip:flip@F` | flips the last plane |
//! | `crop:on@F`, `crop:off@F` | switches the crop box (on: the whole volume the first time) |
//! | `crop:min:X,Y,Z@F`, `crop:max:X,Y,Z@F` | a corner of the crop box, in the volume's frame |
//!
//! e.g. `--script "orbit:30,0@10;zoom:2@20"`.

use anyhow::{bail, Context, Result};
use dvr_engine::scene::transfer_ref::is_path;
use dvr_engine::scene::{Cut, MAX_CLIP_PLANES};
use dvr_engine::session::{Anatomical, Edit};
use dvr_engine::transfer::TransferFunction;
use glam::DVec3;
use winit::event::MouseButton;
use winit::keyboard::{Key as WinitKey, NamedKey};

/// The explorer's keyboard shortcuts (also listed by the help overlay).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    Reset,
    Fit,
    /// Look from one side of the patient (keys 1–6).
    View(Anatomical),
    /// Every cut off, or back on.
    Cut,
    Help,
    Screenshot,
    ToggleUi,
}

/// (keys, what) for the help overlay and the README.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("left drag", "orbit"),
    ("right / middle drag", "pan"),
    ("wheel", "zoom"),
    ("R", "reset the camera"),
    ("F", "fly to fit the volume"),
    (
        "1 – 6",
        "view from the anterior, posterior, left, right, superior, inferior side",
    ),
    ("C", "cuts (clip planes, crop box) off / on"),
    ("H / F1", "this help"),
    ("F12", "screenshot (PNG of the window, EXR of the frame)"),
    ("Tab", "hide / show the panel"),
    ("Esc", "quit"),
];

impl Key {
    pub fn from_winit(key: &WinitKey) -> Option<Self> {
        match key {
            WinitKey::Named(NamedKey::F1) => Some(Key::Help),
            WinitKey::Named(NamedKey::F12) => Some(Key::Screenshot),
            WinitKey::Named(NamedKey::Tab) => Some(Key::ToggleUi),
            WinitKey::Character(c) => Self::from_name(c),
            _ => None,
        }
    }

    fn from_name(name: &str) -> Option<Self> {
        match name.to_ascii_lowercase().as_str() {
            "r" => Some(Key::Reset),
            "f" => Some(Key::Fit),
            "c" => Some(Key::Cut),
            "h" | "f1" => Some(Key::Help),
            "f12" => Some(Key::Screenshot),
            "tab" => Some(Key::ToggleUi),
            d @ ("1" | "2" | "3" | "4" | "5" | "6") => {
                let i = d.parse::<usize>().ok()? - 1;
                Some(Key::View(Anatomical::ALL[i]))
            }
            other => Anatomical::from_name(other).map(Key::View),
        }
    }
}

/// What a drag does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DragKind {
    Orbit,
    Pan,
}

impl DragKind {
    pub fn from_button(b: MouseButton) -> Option<Self> {
        match b {
            MouseButton::Left => Some(DragKind::Orbit),
            MouseButton::Right | MouseButton::Middle => Some(DragKind::Pan),
            _ => None,
        }
    }
}

/// One input command, from the mouse, the keyboard or a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Drag(DragKind, f64, f64),
    Zoom(f64),
    Key(Key),
    Denoiser(String),
    /// The right-hand denoiser of a split view; `None` ends the split.
    Split(Option<String>),
    /// A transfer function in place of the current one.
    Tf(Box<TransferFunction>),
    /// An edit of the clip planes or the crop box.
    Clip(ClipCommand),
    /// Resize the window so the view is (width, height) pixels.
    Resize(u32, u32),
    /// A change to channel `i` (the channels panel).
    Channel(usize, ChannelCommand),
    /// The time slider set to a time point.
    Time(f64),
    /// Playback on or off.
    Play(bool),
    /// A change to one label of the label map (`None`: every label; the labels panel).
    Label(Option<u16>, LabelCommand),
    /// What lies under view pixel (x, y) (a click that is not a drag).
    Pick(f64, f64),
}

/// What a `label:` script command does (the labels panel's controls).
#[derive(Clone, Debug, PartialEq)]
pub enum LabelCommand {
    Visible(bool),
    Colour([f32; 3]),
    Opacity(f32),
}

/// What a `channel:` script command does (the channels panel's controls).
#[derive(Clone, Debug, PartialEq)]
pub enum ChannelCommand {
    Visible(bool),
    /// The TF editor edits this channel from now on (`tf:` commands too).
    Select,
    Colour([f32; 3]),
}

/// What a `clip:`/`crop:` script command does (the panel's buttons and sliders).
#[derive(Clone, Debug, PartialEq)]
pub enum ClipCommand {
    AddPlane,
    Offset(f64),
    Flip,
    Crop(bool),
    CropMin(DVec3),
    CropMax(DVec3),
}

impl ClipCommand {
    /// Applies the command to `cut`; `forward` is where the view looks.
    pub fn apply(&self, cut: &mut Cut, forward: DVec3) {
        match *self {
            ClipCommand::AddPlane if cut.planes.len() < MAX_CLIP_PLANES => {
                cut.planes.push(super::cut_panel::plane_facing(forward));
            }
            ClipCommand::AddPlane => {}
            ClipCommand::Offset(d) => {
                if let Some(p) = cut.planes.last_mut() {
                    p.point += p.normal.normalize_or(DVec3::Z) * d;
                }
            }
            ClipCommand::Flip => {
                if let Some(p) = cut.planes.last_mut() {
                    *p = p.flipped();
                }
            }
            ClipCommand::Crop(on) => match &mut cut.crop {
                Some(c) => c.enabled = on,
                None if on => cut.crop = Some(super::cut_panel::full_box()),
                None => {}
            },
            ClipCommand::CropMin(v) | ClipCommand::CropMax(v) => {
                let c = cut.crop.get_or_insert_with(super::cut_panel::full_box);
                if matches!(self, ClipCommand::CropMin(_)) {
                    c.min = v.clamp(DVec3::splat(-0.5), c.max);
                } else {
                    c.max = v.clamp(c.min, DVec3::splat(0.5));
                }
            }
        }
    }
}

/// The session edit a camera command is; `None` for commands that are not the camera's.
pub fn camera_edit(command: &Command) -> Option<Edit> {
    Some(match *command {
        Command::Drag(DragKind::Orbit, dx, dy) => Edit::Orbit { dx, dy },
        Command::Drag(DragKind::Pan, dx, dy) => Edit::Pan { dx, dy },
        Command::Zoom(steps) => Edit::Zoom { steps },
        Command::Key(Key::Reset) => Edit::ResetCamera,
        Command::Key(Key::Fit) => Edit::FitCamera,
        Command::Key(Key::View(side)) => Edit::ViewFrom(side),
        _ => return None,
    })
}

/// The pointer as the camera sees it: which drag is under way and where it was.
#[derive(Clone, Debug, Default)]
pub struct Pointer {
    pub position: Option<(f64, f64)>,
    pub drag: Option<DragKind>,
    /// Whether the left button went down and came up without the cursor moving (a
    /// click picks; a drag orbits).
    pub clicked: bool,
}

impl Pointer {
    /// A cursor move; returns the drag command it makes, if a drag is under way.
    pub fn moved(&mut self, x: f64, y: f64) -> Option<Command> {
        let last = self.position.replace((x, y));
        match (self.drag, last) {
            (Some(kind), Some((lx, ly))) if (x, y) != (lx, ly) => {
                self.clicked = false;
                Some(Command::Drag(kind, x - lx, y - ly))
            }
            _ => None,
        }
    }

    /// A button press over the view.
    pub fn pressed(&mut self, button: MouseButton) {
        self.drag = DragKind::from_button(button);
        self.clicked = button == MouseButton::Left;
    }

    /// A button release: a pick where the left button clicked without dragging.
    pub fn released(&mut self) -> Option<Command> {
        self.drag = None;
        let (x, y) = self.position?;
        std::mem::take(&mut self.clicked).then_some(Command::Pick(x, y))
    }
}

/// Commands to play at given frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    events: Vec<(u64, Command)>,
}

impl Script {
    pub fn parse(text: &str) -> Result<Self> {
        let mut events = Vec::new();
        for part in text.split(';').map(str::trim).filter(|p| !p.is_empty()) {
            let (body, frame) = part
                .rsplit_once('@')
                .with_context(|| format!("script command {part:?} has no @FRAME"))?;
            let frame: u64 = frame
                .trim()
                .parse()
                .with_context(|| format!("script command {part:?}: bad frame"))?;
            let (action, args) = body
                .split_once(':')
                .with_context(|| format!("script command {part:?} is not ACTION:ARGS@FRAME"))?;
            let pair = || -> Result<(f64, f64)> {
                let (a, b) = args
                    .split_once(',')
                    .with_context(|| format!("script command {part:?} needs DX,DY"))?;
                Ok((
                    a.trim().parse().context("bad DX")?,
                    b.trim().parse().context("bad DY")?,
                ))
            };
            let command = match action.trim() {
                "orbit" => {
                    let (dx, dy) = pair()?;
                    Command::Drag(DragKind::Orbit, dx, dy)
                }
                "pan" => {
                    let (dx, dy) = pair()?;
                    Command::Drag(DragKind::Pan, dx, dy)
                }
                "zoom" => Command::Zoom(
                    args.trim()
                        .parse()
                        .with_context(|| format!("script command {part:?}: bad STEPS"))?,
                ),
                "key" => Command::Key(Key::from_name(args.trim()).with_context(|| {
                    format!("script command {part:?}: unknown key (r, f, c, h, f12, tab)")
                })?),
                "size" => {
                    let (w, h) = args
                        .trim()
                        .split_once('x')
                        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
                        .filter(|&(w, h): &(u32, u32)| (16..=8192).contains(&w) && (16..=8192).contains(&h))
                        .with_context(|| format!("script command {part:?}: needs WxH, 16 to 8192 each"))?;
                    Command::Resize(w, h)
                }
                "clip" => Command::Clip(match args.trim().split_once(':') {
                    None if args.trim() == "add" => ClipCommand::AddPlane,
                    None if args.trim() == "flip" => ClipCommand::Flip,
                    Some(("offset", d)) => ClipCommand::Offset(
                        d.trim()
                            .parse()
                            .ok()
                            .filter(|d: &f64| d.is_finite())
                            .with_context(|| format!("script command {part:?}: bad offset"))?,
                    ),
                    _ => bail!("script command {part:?}: clip:add, clip:flip or clip:offset:D"),
                }),
                "crop" => Command::Clip(match args.trim().split_once(':') {
                    None if args.trim() == "on" => ClipCommand::Crop(true),
                    None if args.trim() == "off" => ClipCommand::Crop(false),
                    Some((corner @ ("min" | "max"), xyz)) => {
                        let v: Vec<f64> = xyz
                            .split(',')
                            .map(|c| c.trim().parse::<f64>())
                            .collect::<Result<_, _>>()
                            .ok()
                            .filter(|v: &Vec<f64>| v.len() == 3 && v.iter().all(|c| c.is_finite()))
                            .with_context(|| format!("script command {part:?}: needs X,Y,Z"))?;
                        let v = DVec3::new(v[0], v[1], v[2]);
                        if corner == "min" {
                            ClipCommand::CropMin(v)
                        } else {
                            ClipCommand::CropMax(v)
                        }
                    }
                    _ => bail!(
                        "script command {part:?}: crop:on, crop:off, crop:min:X,Y,Z or crop:max:X,Y,Z"
                    ),
                }),
                "channel" => {
                    let usage = || {
                        format!("script command {part:?}: channel:I:on, channel:I:off, channel:I:select or channel:I:colour:R,G,B")
                    };
                    let (i, what) = args.trim().split_once(':').with_context(usage)?;
                    let i: usize = i.trim().parse().ok().with_context(usage)?;
                    let change = match what.trim().split_once(':') {
                        None if what.trim() == "on" => ChannelCommand::Visible(true),
                        None if what.trim() == "off" => ChannelCommand::Visible(false),
                        None if what.trim() == "select" => ChannelCommand::Select,
                        Some(("colour" | "color", rgb)) => {
                            let v: Vec<f32> = rgb
                                .split(',')
                                .map(|c| c.trim().parse::<f32>())
                                .collect::<Result<_, _>>()
                                .ok()
                                .filter(|v: &Vec<f32>| v.len() == 3 && v.iter().all(|c| (0.0..=1.0).contains(c)))
                                .with_context(usage)?;
                            ChannelCommand::Colour([v[0], v[1], v[2]])
                        }
                        _ => bail!(usage()),
                    };
                    Command::Channel(i, change)
                }
                "label" => {
                    let usage = || {
                        format!("script command {part:?}: label:V|all:on, label:V|all:off, label:V|all:colour:R,G,B or label:V|all:opacity:O")
                    };
                    let (v, what) = args.trim().split_once(':').with_context(usage)?;
                    let value = match v.trim() {
                        "all" => None,
                        v => Some(v.parse::<u16>().ok().with_context(usage)?),
                    };
                    let unit = |s: &str| s.trim().parse::<f32>().ok().filter(|c| (0.0..=1.0).contains(c));
                    let change = match what.trim().split_once(':') {
                        None if what.trim() == "on" => LabelCommand::Visible(true),
                        None if what.trim() == "off" => LabelCommand::Visible(false),
                        Some(("colour" | "color", rgb)) => {
                            let v: Vec<f32> = rgb.split(',').map(unit).collect::<Option<_>>().filter(|v: &Vec<f32>| v.len() == 3).with_context(usage)?;
                            LabelCommand::Colour([v[0], v[1], v[2]])
                        }
                        Some(("opacity", o)) => LabelCommand::Opacity(unit(o).with_context(usage)?),
                        _ => bail!(usage()),
                    };
                    Command::Label(value, change)
                }
                "pick" => {
                    let usage = || format!("script command {part:?}: pick:X,Y (view pixels)");
                    let v: Vec<f64> = args
                        .split(',')
                        .map(|c| c.trim().parse::<f64>().ok().filter(|c| c.is_finite() && *c >= 0.0))
                        .collect::<Option<_>>()
                        .filter(|v: &Vec<f64>| v.len() == 2)
                        .with_context(usage)?;
                    Command::Pick(v[0], v[1])
                }
                "time" => Command::Time(
                    args.trim()
                        .parse()
                        .ok()
                        .filter(|t: &f64| t.is_finite() && *t >= 0.0)
                        .with_context(|| format!("script command {part:?}: time:T, a time point >= 0"))?,
                ),
                "play" => match args.trim() {
                    "on" => Command::Play(true),
                    "off" => Command::Play(false),
                    _ => bail!("script command {part:?}: play:on or play:off"),
                },
                "denoiser" => Command::Denoiser(args.trim().to_string()),
                "split" => match args.trim() {
                    "off" | "" => Command::Split(None),
                    name => Command::Split(Some(name.to_string())),
                },
                "tf" => {
                    let spec = args.trim();
                    let tf = if is_path(spec) {
                        TransferFunction::load(spec)
                    } else {
                        TransferFunction::preset(spec)
                    };
                    Command::Tf(Box::new(
                        tf.with_context(|| format!("script command {part:?}"))?,
                    ))
                }
                other => bail!(
                    "script command {part:?}: unknown action {other:?} \
                     (orbit, pan, zoom, key, denoiser, split, tf, size, clip, crop, channel, time, play)"
                ),
            };
            events.push((frame, command));
        }
        events.sort_by_key(|(f, _)| *f);
        Ok(Self { events })
    }

    /// The commands due at `frame`.
    pub fn at(&self, frame: u64) -> impl Iterator<Item = &Command> {
        self.events
            .iter()
            .filter(move |(f, _)| *f == frame)
            .map(|(_, c)| c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_command_and_sorts_by_frame() {
        let s = Script::parse(
            "zoom:2@20; orbit:30,0@10;pan:-5,7.5@10;key:F@3;denoiser:svgf@1;split:taa@2;\
             split:off@4;tf:phantom-layered@6",
        )
        .expect("parses");
        let at = |f| s.at(f).cloned().collect::<Vec<_>>();
        assert_eq!(
            at(10),
            vec![
                Command::Drag(DragKind::Orbit, 30.0, 0.0),
                Command::Drag(DragKind::Pan, -5.0, 7.5)
            ]
        );
        assert_eq!(at(20), vec![Command::Zoom(2.0)]);
        assert_eq!(at(3), vec![Command::Key(Key::Fit)]);
        assert_eq!(at(1), vec![Command::Denoiser("svgf".into())]);
        assert_eq!(at(2), vec![Command::Split(Some("taa".into()))]);
        assert_eq!(at(4), vec![Command::Split(None)]);
        let soft = TransferFunction::preset("phantom-layered").expect("preset");
        assert_eq!(at(6), vec![Command::Tf(Box::new(soft))]);
        assert!(at(5).is_empty());
    }

    #[test]
    fn bad_scripts_say_what_is_wrong() {
        for (text, needle) in [
            ("orbit:30,0", "@FRAME"),
            ("orbit:30@1", "DX,DY"),
            ("spin:1@1", "unknown action"),
            ("key:q@1", "unknown key"),
            ("zoom:x@1", "STEPS"),
            ("zoom:1@x", "bad frame"),
            ("tf:no-such-preset@1", "no-such-preset"),
            ("tf:missing/tf.toml@1", "missing/tf.toml"),
        ] {
            let e = format!("{:#}", Script::parse(text).expect_err(text));
            assert!(e.contains(needle), "{text}: {e}");
        }
    }

    #[test]
    fn a_drag_is_the_difference_of_cursor_positions() {
        let mut p = Pointer::default();
        assert_eq!(p.moved(10.0, 10.0), None);
        p.drag = Some(DragKind::Orbit);
        assert_eq!(
            p.moved(14.0, 7.0),
            Some(Command::Drag(DragKind::Orbit, 4.0, -3.0))
        );
        p.drag = None;
        assert_eq!(p.moved(20.0, 20.0), None);
    }

    #[test]
    fn camera_commands_are_the_sessions_mouse_edits() {
        let cmd = Script::parse("orbit:30,0@10;pan:-2,3@10;zoom:1.5@10;key:r@10;key:f@10")
            .expect("parses");
        let edits: Vec<Option<Edit>> = cmd.at(10).map(camera_edit).collect();
        assert_eq!(
            edits,
            vec![
                Some(Edit::Orbit { dx: 30.0, dy: 0.0 }),
                Some(Edit::Pan { dx: -2.0, dy: 3.0 }),
                Some(Edit::Zoom { steps: 1.5 }),
                Some(Edit::ResetCamera),
                Some(Edit::FitCamera),
            ]
        );
        assert_eq!(camera_edit(&Command::Key(Key::Help)), None);
    }

    #[test]
    fn keys_one_to_six_and_side_names_are_the_anatomical_views() {
        let cmd = Script::parse("key:1@0;key:4@0;key:6@0;key:superior@0").expect("parses");
        let edits: Vec<Option<Edit>> = cmd.at(0).map(camera_edit).collect();
        assert_eq!(
            edits,
            vec![
                Some(Edit::ViewFrom(Anatomical::Anterior)),
                Some(Edit::ViewFrom(Anatomical::Right)),
                Some(Edit::ViewFrom(Anatomical::Inferior)),
                Some(Edit::ViewFrom(Anatomical::Superior)),
            ]
        );
        assert_eq!(Key::from_name("7"), None);
    }
}
