//! The frame: scripted commands, the UI, model application, then render and present;
//! and what happens to a finished frame's results (timings, screenshots, recording).

use super::*;

/// Frames left out of the frame-rate summary (pipeline compilation on first use).
const WARMUP_FRAMES: usize = 5;

/// The frame after which device memory is first sampled for the summary (a scripted
/// warm-up has made every kind of edit by then).
const MEMORY_WARMUP_FRAMES: u64 = 40;

impl Explorer {
    /// One frame: see the module docs.
    pub(super) fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(window) = self.window.clone() else {
            return Ok(());
        };
        let size = window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(()); // minimised
        }
        let now = Instant::now();
        if let Some(t) = self.frame_started.replace(now) {
            // The interval that just ended is the last frame's, at its divisor.
            let ms = (now - t).as_secs_f32() * 1000.0;
            self.frame_ms.push((ms, self.ui.stats.divisor.max(1)));
        }
        if let Some(gfx) = self.gfx.as_mut() {
            let e = gfx.swapchain.extent;
            if self.resized || (e.width, e.height) != (size.width, size.height) {
                gfx.recreate_swapchain(size)?;
                self.resized = false;
            }
        }
        self.ui.playback.tick(&mut self.model.time);
        let due: Vec<Command> = self.script.at(self.frame).cloned().collect();
        for c in &due {
            self.command(c);
        }

        // The UI edits the model; it outlines the cut over the view it shows.
        self.ui.view = self.view_geometry();
        let Some(egui_state) = self.egui_state.as_mut() else {
            return Ok(());
        };
        let raw = egui_state.take_egui_input(&window);
        let (ui_state, model) = (&mut self.ui, &mut self.model);
        let mut requests = ui::UiRequests::default();
        let output = self.egui_ctx.run_ui(raw, |ui| {
            requests = ui::draw(ui, ui_state, model);
        });
        egui_state.handle_platform_output(&window, output.platform_output);
        if requests.screenshot {
            self.shots.push(self.frame);
        }
        let primitives = self
            .egui_ctx
            .tessellate(output.shapes, output.pixels_per_point);
        // Texture uploads now; frees once the frames drawing with them are done.
        let mut textures = output.textures_delta;
        self.free_textures.extend(textures.free.drain());
        let uploaded = match self.gfx.as_mut() {
            Some(gfx) => match gfx.overlay.as_mut() {
                Some(o) => {
                    o.set_primitives(primitives, output.pixels_per_point);
                    o.set_textures(&gfx.ctx, &textures)
                }
                None => Ok(()),
            },
            None => Ok(()),
        };
        textures.clear();
        uploaded?;
        for r in self.apply_model()? {
            self.completed(r)?;
        }

        // Render and present: at 1/k of the view per side while it moves (moving.rs).
        let (vw, vh) = self.view_size();
        let Some(view) = self
            .gfx
            .as_ref()
            .and_then(|g| g.session.as_ref())
            .map(|s| s.view().clone())
        else {
            return Ok(());
        };
        let changed = self.last_view.as_ref().is_some_and(|last| *last != view);
        let held = self.pointer.drag.is_some() || self.ui.tf_editor.dragging.is_some();
        let divisor = self.moving.next(changed, held);
        let (rw, rh) = moving::reduced((vw, vh), divisor);
        let want_shot = self.shots.contains(&self.frame);
        let readback_hdr = want_shot || self.recorder.is_some();
        let split = (self.denoiser_list().len() == 2)
            .then(|| ((vw as f32 * self.model.split) as u32).clamp(1, vw - 1));
        let want_present_copy = want_shot || self.args.screenshot.is_some();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let (Some(session), Some(overlay)) = (gfx.session.as_mut(), gfx.overlay.as_ref()) else {
            return Ok(());
        };
        let shown = Extent {
            width: vw,
            height: vh,
        };
        let rendered = Extent {
            width: rw,
            height: rh,
        };
        let finished = session.resize(shown, rendered)?;
        self.ui.stats.render_size = (rw, rh);
        self.ui.stats.divisor = divisor;
        self.ui.stats.view = (vw, vh);
        self.ui.stats.volume = session.renderer()?.volume_residency().to_string();
        let Some(image) = gfx.swapchain.acquire()? else {
            gfx.recreate_swapchain(size)?;
            return Ok(());
        };
        let bg = ui::PANEL_FILL.to_normalized_gamma_f32();
        let target = PresentTarget {
            image,
            left: 0,
            right: split.map(|_| 1),
            layout: PresentLayout {
                offset: [0, 0],
                size: Some([vw, vh]),
                split_x: split,
                exposure: self.model.exposure,
                background: [bg[0], bg[1], bg[2]],
            },
            readback: want_present_copy && gfx.swapchain.readable,
            overlay: Some(overlay),
        };
        let request = FrameRequest {
            readback: readback_hdr,
            reset: false,
            aux: false,
            features: false,
        };
        let result = session.frame(&request, Some(&target))?;
        self.in_flight.push_back((divisor, (rw, rh)));
        if !gfx.swapchain.present(&gfx.ctx, &image)? {
            self.resized = true;
        }
        if !self.free_textures.is_empty() {
            gfx.ctx.wait_idle()?;
            if let Some(o) = gfx.overlay.as_mut() {
                o.free_textures(&std::mem::take(&mut self.free_textures))?;
            }
        }
        if let Some(rec) = self.recorder.as_mut() {
            rec.push(&view, &self.model.left)?;
        }
        self.last_view = Some(view);
        self.frame += 1;
        for r in finished.into_iter().chain(result) {
            self.completed(r)?;
        }
        if self.args.frames.is_some_and(|n| self.frame >= n) {
            event_loop.exit();
        }
        Ok(())
    }

    /// The camera and rectangle of the view shown this frame, for the cut's outline and
    /// the orientation cue.
    fn view_geometry(&self) -> Option<cut_panel::ViewGeometry> {
        let session = self.gfx.as_ref()?.session.as_ref()?;
        let (vw, vh) = self.view_size();
        let ppp = self.egui_ctx.pixels_per_point();
        let spec = &session.view().camera;
        let camera = spec.camera();
        let volume = &session.setup().volume;
        let half = glam::Vec3::from(volume.world_size).as_dvec3() * 0.5;
        let forward = camera.forward().as_dvec3();
        Some(cut_panel::ViewGeometry {
            view_proj: camera.view_proj(vw as f32 / vh as f32),
            forward,
            half,
            target: spec.target,
            right: forward.cross(spec.up).normalize_or(glam::DVec3::X),
            mm_per_unit: f64::from(volume.mm_per_unit),
            rect: egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(vw as f32 / ppp, vh as f32 / ppp),
            ),
        })
    }

    /// Handles the results of a finished frame: timings, screenshots, recorded frames.
    pub(super) fn completed(&mut self, r: FrameResult) -> Result<()> {
        let frame_ms = self.frame_ms.last().map_or(0.0, |f| f.0);
        let (divisor, (w, h)) = self
            .in_flight
            .pop_front()
            .unwrap_or((1, self.ui.stats.render_size));
        self.moving.finished(divisor, ui::gpu_span_ms(&r.timings));
        let shown = r.images.first();
        if let Some(rec) = &self.recorder {
            if let Some((_, pixels)) = shown {
                if pixels.len() == (w * h) as usize {
                    write_png(&rec.frame_path(r.index), &to_rgb(w, h, pixels))?;
                }
            }
        }
        if let Some(pos) = self.shots.iter().position(|&f| f == r.index) {
            self.shots.remove(pos);
            let stem = PathBuf::from(format!("dvr-explore-{:04}", self.shot_count));
            self.shot_count += 1;
            let mut saved = Vec::new();
            if let Some(s) = &r.screenshot {
                let path = stem.with_extension("png");
                save_screenshot(&path, s)?;
                saved.push(path);
            }
            if let Some((_, pixels)) = shown {
                if pixels.len() == (w * h) as usize {
                    let path = stem.with_extension("exr");
                    write_exr(&path, &to_rgb(w, h, pixels))?;
                    saved.push(path);
                }
            }
            let names: Vec<String> = saved.iter().map(|p| p.display().to_string()).collect();
            self.ui.set_status(format!("saved {}", names.join(", ")));
            println!("explore: saved {}", names.join(", "));
        }
        if r.screenshot.is_some() {
            self.last_screenshot = r.screenshot;
        }
        // Device and resident memory after the warm-up and on the last frame: a script
        // that ends in its warm-up's state (size, denoiser, split) compares like with like,
        // and what the graph holds follows the recent frames, so a leak shows as growth.
        if let (Some(g), Some(n)) = (self.gfx.as_ref(), self.args.frames) {
            if r.index == MEMORY_WARMUP_FRAMES || r.index + 1 == n {
                let at = usize::from(r.index + 1 == n);
                self.memory_samples[at] = (g.ctx.memory_in_use().allocated, resident_bytes());
            }
        }
        if r.index >= WARMUP_FRAMES as u64 {
            self.gpu_spans.push(ui::gpu_span_ms(&r.timings));
            for t in &r.timings {
                match self.pass_totals.iter_mut().find(|p| p.0 == t.pass) {
                    Some(p) => {
                        p.1 += t.ms;
                        p.2 += 1;
                    }
                    None => self.pass_totals.push((t.pass.clone(), t.ms, 1)),
                }
            }
        }
        self.ui.stats.push(frame_ms, r.timings);
        Ok(())
    }

    /// After the event loop: the last frames' results, `--screenshot`, the recorded
    /// scene, the frame-rate summary, and the first error if there was one.
    pub(super) fn finish(&mut self) -> Result<()> {
        if let Some(e) = self.error.take() {
            self.gfx = None;
            return Err(e);
        }
        let flushed = match self.gfx.as_mut().and_then(|g| g.session.as_mut()) {
            Some(r) => r.flush()?,
            None => Vec::new(),
        };
        for r in flushed {
            self.completed(r)?;
        }
        let summary = self.gfx.as_ref().map(|g| {
            (
                g.ctx.info.name.clone(),
                format!("{:?}", g.swapchain.present_mode),
            )
        });

        self.gfx = None;
        if let Some(path) = &self.args.screenshot {
            let shot = self.last_screenshot.as_ref().with_context(|| {
                format!(
                    "--screenshot {}: no frame was read back (the surface does not allow \
                     copying from swapchain images, or no frame was presented)",
                    path.display()
                )
            })?;
            save_screenshot(path, shot)?;
            println!("explore: wrote {}", path.display());
        }
        if let Some(rec) = &self.recorder {
            if let Some(path) = rec.finish(&self.scene, self.args.render.volume_size)? {
                println!(
                    "explore: recorded {} frames; replay with: dvr capture --scene {} --size {}x{} \
                     --volume-size {} --motion {} --denoiser {}",
                    rec.frame_count(),
                    path.display(),
                    self.ui.stats.render_size.0,
                    self.ui.stats.render_size.1,
                    self.args.render.volume_size,
                    self.args.render.motion,
                    self.model.left,
                );
            }
        }
        let [(warm, rss_warm), (end, rss_end)] = self.memory_samples;
        if warm > 0 && end > 0 {
            let mib = |b: u64| b as f64 / (1 << 20) as f64;
            let resident = match (rss_warm, rss_end) {
                (Some(w), Some(e)) => format!(
                    "; resident memory {:.1} MiB after frame {MEMORY_WARMUP_FRAMES}, {:.1} MiB after the last",
                    mib(w),
                    mib(e)
                ),
                _ => String::new(),
            };
            println!(
                "explore: GPU memory {:.3} MiB allocated after frame {MEMORY_WARMUP_FRAMES}, \
                 {:.3} MiB after the last{resident}",
                mib(warm),
                mib(end)
            );
        }
        let timed: Vec<(f32, u32)> = self.frame_ms.iter().skip(WARMUP_FRAMES).copied().collect();
        if let (Some((device, mode)), false) = (summary, timed.is_empty()) {
            let mean = timed.iter().map(|f| f.0).sum::<f32>() / timed.len() as f32;
            println!(
                "explore: {} frames in {:.1} s; {:.1} ms/frame ({:.2} fps) after {WARMUP_FRAMES} \
                 warm-up frames, view {}x{}, {device}, {mode}",
                self.frame,
                self.started.elapsed().as_secs_f64(),
                mean,
                1000.0 / mean,
                self.ui.stats.view.0,
                self.ui.stats.view.1,
            );
            if timed.iter().any(|f| f.1 > 1) {
                let mut divisors: Vec<u32> = timed.iter().map(|f| f.1).collect();
                divisors.sort_unstable();
                divisors.dedup();
                let groups: Vec<String> = divisors
                    .iter()
                    .map(|&k| {
                        let ms: Vec<f32> = timed.iter().filter(|f| f.1 == k).map(|f| f.0).collect();
                        let mean = ms.iter().sum::<f32>() / ms.len() as f32;
                        let what = if k == 1 {
                            "full size".to_string()
                        } else {
                            format!("1/{k}")
                        };
                        format!("{what}: {} frames, {mean:.1} ms/frame", ms.len())
                    })
                    .collect();
                println!(
                    "explore: by rendered size (--moving-ms): {}",
                    groups.join("; ")
                );
            }
            let passes: Vec<String> = self
                .pass_totals
                .iter()
                .map(|(pass, ms, n)| format!("{pass} {:.1}", ms / f64::from(*n)))
                .collect();
            if !passes.is_empty() {
                let span = self.gpu_spans.iter().sum::<f64>() / self.gpu_spans.len().max(1) as f64;
                println!(
                    "explore: GPU frame span {span:.1} ms; ms per pass: {}",
                    passes.join(", ")
                );
            }
        }
        Ok(())
    }
}

pub(super) fn save_screenshot(path: &Path, s: &Screenshot) -> Result<()> {
    let rgb: Vec<u8> = s
        .rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let png = dvr_engine::image_io::encode_srgb8_png(path, s.width, s.height, &rgb)?;
    dvr_engine::image_io::write_file(path, &png, dvr_engine::files::Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}

/// This process's resident memory (VmRSS of /proc/self/status), where the system has it.
fn resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
