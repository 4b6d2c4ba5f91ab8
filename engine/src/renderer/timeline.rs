//! A series played in time: the volume at a fractional time point, made from the two
//! time points around it (linear interpolation of the packed texels), with only the
//! time points in use resident and the next one read on a background thread while the
//! current one renders. The renderer uploads whichever volume a frame's inputs name.

use super::uploads::{BrickRanges, VolumeFormat, VolumeUpload};
use crate::error::{EngineError, Result};
use crate::volume::Series;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Time points held at once: the two a fractional time interpolates, the one read
/// ahead, and the interpolated volume.
const RESIDENT: usize = 3;

type Loading = JoinHandle<std::result::Result<VolumeUpload, String>>;

/// The time points of a series as uploads, read on demand.
pub struct Timeline {
    series: Arc<Series>,
    times: usize,
    resident: Mutex<VecDeque<(usize, Arc<VolumeUpload>)>>,
    /// The last fractional time asked for and its volume (a held frame asks again).
    last: Mutex<Option<(u64, Arc<VolumeUpload>)>>,
    ahead: Mutex<Option<(usize, Loading)>>,
}

impl std::fmt::Debug for Timeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Timeline")
            .field("times", &self.times)
            .finish()
    }
}

impl Timeline {
    /// A timeline over `series`, whose time point 0 is `first` (already read and packed).
    pub fn new(series: Arc<Series>, first: Arc<VolumeUpload>) -> Self {
        let times = series.info().times;
        Self {
            series,
            times,
            resident: Mutex::new(VecDeque::from([(0, first)])),
            last: Mutex::new(None),
            ahead: Mutex::new(None),
        }
    }

    pub fn times(&self) -> usize {
        self.times
    }

    /// The volume at `time` (0 to times − 1; fractional times interpolate the two time
    /// points around it). Starts reading the time point after those on a background
    /// thread. An error names the time asked for and the series' range, or the file.
    pub fn at(&self, time: f64) -> Result<Arc<VolumeUpload>> {
        let last_time = (self.times - 1) as f64;
        if !(time.is_finite() && (0.0..=last_time).contains(&time)) {
            return Err(EngineError::Resource {
                resource: format!("series {:?}", self.series.info().name),
                problem: format!(
                    "time {time} is outside its time points 0 to {last_time} ({} in all)",
                    self.times
                ),
            });
        }
        let key = time.to_bits();
        if let Some((k, v)) = &*lock(&self.last) {
            if *k == key {
                return Ok(v.clone());
            }
        }
        let t0 = time.floor() as usize;
        let frac = (time - t0 as f64) as f32;
        let a = self.point(t0)?;
        let v = if frac > 0.0 {
            let b = self.point(t0 + 1)?;
            Arc::new(lerp(&a, &b, frac))
        } else {
            a
        };
        let next = t0 + if frac > 0.0 { 2 } else { 1 };
        self.read_ahead(next);
        *lock(&self.last) = Some((key, v.clone()));
        Ok(v)
    }

    /// Time point `t`, resident, read ahead, or read now.
    fn point(&self, t: usize) -> Result<Arc<VolumeUpload>> {
        if let Some((_, v)) = lock(&self.resident).iter().find(|(i, _)| *i == t) {
            return Ok(v.clone());
        }
        let ahead = lock(&self.ahead).take();
        let loaded = match ahead {
            Some((i, handle)) if i == t => handle
                .join()
                .unwrap_or_else(|_| Err(format!("reading time point {t} panicked"))),
            other => {
                // A read ahead of another time point is left to finish and dropped.
                drop(other);
                read(&self.series, t)
            }
        }
        .map_err(|problem| EngineError::Resource {
            resource: format!("series {:?} at time point {t}", self.series.info().name),
            problem,
        })?;
        let v = Arc::new(loaded);
        let mut resident = lock(&self.resident);
        resident.push_back((t, v.clone()));
        while resident.len() > RESIDENT {
            resident.pop_front();
        }
        Ok(v)
    }

    fn read_ahead(&self, t: usize) {
        if t >= self.times || lock(&self.resident).iter().any(|(i, _)| *i == t) {
            return;
        }
        let mut ahead = lock(&self.ahead);
        if matches!(&*ahead, Some((i, _)) if *i == t) {
            return;
        }
        let series = self.series.clone();
        *ahead = Some((t, std::thread::spawn(move || read(&series, t))));
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Time point `t` read and packed.
fn read(series: &Series, t: usize) -> std::result::Result<VolumeUpload, String> {
    let channels = series.read(t).map_err(|e| e.to_string())?;
    VolumeUpload::from_channels(&channels)
}

/// `a` and `b` (one grid, one format) mixed as (1 − f) a + f b, texel by texel. Each
/// brick's range bounds the mix's (a linear mix stays between its ends), so the
/// majorants stay bounds without a pass over the voxels.
pub fn lerp(a: &VolumeUpload, b: &VolumeUpload, f: f32) -> VolumeUpload {
    let mix = |x: f32, y: f32| x + (y - x) * f;
    let pairs = |n: usize| a.bytes.chunks_exact(n).zip(b.bytes.chunks_exact(n));
    let bytes: Vec<u8> = match a.format {
        VolumeFormat::R8 => pairs(1)
            .map(|(x, y)| mix(f32::from(x[0]), f32::from(y[0])).round() as u8)
            .collect(),
        VolumeFormat::R16 => pairs(2)
            .flat_map(|(x, y)| {
                let (p, q) = (
                    u16::from_le_bytes([x[0], x[1]]),
                    u16::from_le_bytes([y[0], y[1]]),
                );
                (mix(f32::from(p), f32::from(q)).round() as u16).to_le_bytes()
            })
            .collect(),
        VolumeFormat::R32F => pairs(4)
            .flat_map(|(x, y)| {
                let p = f32::from_le_bytes([x[0], x[1], x[2], x[3]]);
                let q = f32::from_le_bytes([y[0], y[1], y[2], y[3]]);
                mix(p, q).to_le_bytes()
            })
            .collect(),
    };
    VolumeUpload {
        name: a.name.clone(),
        dims: a.dims,
        format: a.format,
        bytes,
        blocks: None,
        world_size: a.world_size,
        window: a.window,
        mm_per_unit: a.mm_per_unit,
        bricks: union(&a.bricks, &b.bricks),
        extra_channels: a
            .extra_channels
            .iter()
            .zip(&b.extra_channels)
            .map(|(x, y)| super::uploads::ChannelUpload {
                bricks: union(&x.bricks, &y.bricks),
                ..x.clone()
            })
            .collect(),
    }
}

fn union(a: &BrickRanges, b: &BrickRanges) -> BrickRanges {
    BrickRanges {
        min: a.min.iter().zip(&b.min).map(|(x, y)| x.min(*y)).collect(),
        max: a.max.iter().zip(&b.max).map(|(x, y)| x.max(*y)).collect(),
        ..a.clone()
    }
}
