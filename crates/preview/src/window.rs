//! The interactive previewer. A winit window shows the running average of the GPU
//! renderer (`gpu::preview::Renderer::accumulate`): every redraw adds frames (f = 0, 1, 2, ...)
//! until `MAX_FRAMES` (1024), and the present pass (`gpu::preview::Presenter`) tone maps the average
//! into the window like the pictures `--out` writes (`envmap::tonemap_rgb8`), on the window's
//! surface (`gpu::surface`: the window shows the picture's bytes, up to a rare one-step rounding
//! difference: the GPU applies the exposure in f32). `--window-screenshot` saves what the window
//! shows and exits, for scripts.
//!
//! Controls: drag with the left button to orbit (azimuth, elevation), scroll to change the
//! distance, 1/2/3 for the reference, fis and prefiltered modes, D to cycle the views (shaded,
//! normals, the prefiltered layer per pixel, the sample slice per pixel; `gpu::preview::View`),
//! +/- for the exposure in half stops, R to reset the camera, Esc or Q to quit. A change of
//! camera, mode or view starts the accumulation again; the exposure only redraws.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use gpu::preview::{Presenter, Renderer, View};
use gpu::surface::{Display, WindowSurface};
use render::{Camera, Estimator, Settings};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::Error;

type Result<T, E = Error> = std::result::Result<T, E>;

/// Frames a view accumulates before the window stops drawing: far beyond where the average
/// stops changing visibly (the noise falls as 1 / sqrt(frames)), and a bound on the work of a
/// window left open.
const MAX_FRAMES: u32 = 1024;

/// A redraw adds frames for about this long, so that input stays responsive on a slow adapter
/// and a fast one does not spend its time presenting.
const REDRAW_BUDGET_MS: f64 = 40.0;

/// Most frames one redraw adds.
const MAX_FRAMES_PER_REDRAW: u32 = 16;

/// Radians of azimuth or elevation per pixel dragged.
const ORBIT_PER_PIXEL: f32 = 0.01;

/// The distance is multiplied by this per line scrolled away (divided towards).
const ZOOM_PER_LINE: f32 = 1.1;

/// Pixels of a touchpad's scroll that count as one line.
const PIXELS_PER_LINE: f64 = 40.0;

/// The camera stays this far from the centre: outside the unit sphere the meshes are scaled to,
/// with the near plane (`distance / 100`) in front of them.
const DISTANCE_RANGE: (f32, f32) = (1.2, 50.0);

/// Exposure change per key press, in stops.
const EXPOSURE_STEP_EV: f32 = 0.5;

const KEY_HELP: &str = "brdf-preview window: drag (left button) to orbit, scroll to zoom, 1/2/3 reference/fis/prefiltered, \
                        D cycles views (shaded, normals, prefiltered layer, sample slice), +/- exposure, R resets the \
                        camera, Esc/Q quits";

/// Opens a window showing the scene, rendered with the GPU renderer, until it is closed; with
/// `screenshot`, saves what the window shows once `settings.frames` frames are accumulated (1
/// for a debug view) and closes it, returning a line that says what the picture shows. Fails
/// with "--window needs a display: ...; render to a file with --out" where no window can open.
pub fn run(
    material: &render::Material,
    lighting: &render::Lighting,
    scene: &render::Scene,
    settings: &render::Settings,
    tone_mapping: &envmap::ToneMapping,
    screenshot: Option<&Path>,
) -> Result<Option<String>> {
    // Elsewhere (macOS, Windows) there is always a display to ask.
    if cfg!(all(unix, not(target_os = "macos")))
        && let Some(reason) = missing_display(|name| std::env::var_os(name))
    {
        return Err(no_display(reason));
    }
    let event_loop =
        EventLoop::new().map_err(|e| no_display(format!("opening the event loop: {}", winit_message(&e))))?;
    let display = Display::new(event_loop.owned_display_handle());
    let mut app = App {
        inputs: Inputs { material, lighting, scene, settings, tone_mapping },
        screenshot: screenshot.map(Path::to_path_buf),
        shown: None,
        display,
        state: None,
        outcome: None,
    };
    eprintln!("{KEY_HELP}");
    event_loop.run_app(&mut app).map_err(|e| Error::Window(format!("running the window's event loop: {e}")))?;
    match app.outcome {
        Some(Err(e)) => Err(e),
        Some(Ok(())) | None => Ok(app.shown),
    }
}

/// The error of a machine where no window can open.
fn no_display(reason: impl std::fmt::Display) -> Error {
    Error::Window(format!("--window needs a display: {reason}; render to a file with --out"))
}

/// A winit error without the source location winit puts before an OS error ("os error at
/// src/...rs:788: Failed to open connection to X server"), lower case.
fn winit_message(e: &impl std::fmt::Display) -> String {
    let message = e.to_string();
    let problem = match message.strip_prefix("os error at ") {
        Some(rest) => rest.split_once(": ").map_or(rest, |(_, problem)| problem),
        None => &message,
    };
    let mut chars = problem.chars();
    match chars.next() {
        Some(c) if chars.clone().next().is_some_and(char::is_lowercase) => c.to_lowercase().chain(chars).collect(),
        _ => problem.to_string(),
    }
}

/// Why no window can open, judged from the environment (`var` looks a variable up) the way winit
/// chooses its backend on Linux and the BSDs: `None` where a Wayland or an X11 display is named
/// (a non-empty WAYLAND_DISPLAY, WAYLAND_SOCKET or DISPLAY).
fn missing_display(var: impl Fn(&str) -> Option<OsString>) -> Option<String> {
    let named =
        ["WAYLAND_DISPLAY", "WAYLAND_SOCKET", "DISPLAY"].iter().any(|name| var(name).is_some_and(|v| !v.is_empty()));
    (!named).then(|| "neither DISPLAY nor WAYLAND_DISPLAY is set".to_string())
}

/// What the window renders.
struct Inputs<'a> {
    material: &'a render::Material,
    lighting: &'a render::Lighting,
    scene: &'a render::Scene,
    settings: &'a render::Settings,
    tone_mapping: &'a envmap::ToneMapping,
}

struct App<'a> {
    inputs: Inputs<'a>,
    screenshot: Option<PathBuf>,
    /// What the screenshot shows, once saved.
    shown: Option<String>,
    display: Display,
    /// Made once the event loop runs (winit opens windows only then).
    state: Option<State>,
    /// Set when the loop is asked to exit: what `run` returns.
    outcome: Option<Result<()>>,
}

/// The camera as the mouse moves it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Orbit {
    azimuth: f32,
    elevation: f32,
    distance: f32,
}

impl Orbit {
    fn of(camera: &Camera) -> Orbit {
        Orbit { azimuth: camera.azimuth(), elevation: camera.elevation(), distance: camera.distance() }
    }

    /// The camera looking from here, with `like`'s target and field of view. Keeps the elevation
    /// the camera clamps to, so that dragging past a pole does not wind up.
    fn camera(&mut self, like: &Camera) -> Result<Camera> {
        let camera = Camera::orbit(like.target(), self.distance, self.azimuth, self.elevation, like.fov_y())?;
        self.elevation = camera.elevation();
        Ok(camera)
    }
}

/// The window and everything drawn into it.
struct State {
    window: Arc<Window>,
    surface: WindowSurface,
    gpu: gpu::Gpu,
    renderer: Renderer,
    presenter: Presenter,
    home: Orbit,
    orbit: Orbit,
    /// The orbit the renderer's G-buffer was drawn for.
    drawn: Orbit,
    mode: Estimator,
    view: View,
    exposure_ev: f32,
    /// The cursor's last position, and whether the left button drags it.
    cursor: Option<PhysicalPosition<f64>>,
    dragging: bool,
    /// The last measured time per frame, and how many frames a redraw adds.
    ms_per_frame: Option<f64>,
    frames_per_redraw: u32,
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => {
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => self.finish(event_loop, Err(e)),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(state) = self.state.as_mut() else { return };
        let result = match event {
            WindowEvent::CloseRequested => {
                self.finish(event_loop, Ok(()));
                return;
            }
            WindowEvent::Resized(size) => state.resize(size),
            WindowEvent::KeyboardInput { event, .. } => {
                match state.key(&event, self.inputs.material, self.inputs.lighting) {
                    KeyOutcome::Quit => {
                        self.finish(event_loop, Ok(()));
                        return;
                    }
                    KeyOutcome::Handled => Ok(()),
                }
            }
            WindowEvent::MouseInput { button: MouseButton::Left, state: pressed, .. } => {
                state.dragging = pressed == ElementState::Pressed;
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                state.cursor_moved(position);
                Ok(())
            }
            WindowEvent::CursorLeft { .. } => {
                state.cursor = None;
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                state.scroll(delta);
                Ok(())
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.finish(event_loop, Err(e));
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        // Redraws are requested while there is work; otherwise the loop sleeps until input.
        event_loop.set_control_flow(ControlFlow::Wait);
    }
}

enum KeyOutcome {
    Quit,
    Handled,
}

impl App<'_> {
    /// Opens the window, a device that can present to it and the renderer.
    fn open(&self, event_loop: &ActiveEventLoop) -> Result<State> {
        let scene = self.inputs.scene;
        let attributes = Window::default_attributes()
            .with_title("brdf-preview")
            .with_inner_size(PhysicalSize::new(scene.width as u32, scene.height as u32));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| no_display(format!("opening a window: {}", winit_message(&e))))?,
        );
        let size = window.inner_size();
        let (surface, gpu) =
            WindowSurface::new(&self.display, window.clone(), (size.width, size.height), self.screenshot.is_some())?;
        let renderer = Renderer::new(&gpu, scene, self.inputs.material, self.inputs.lighting)?;
        let presenter = Presenter::new(&gpu, surface.format())?;
        eprintln!("window: {}x{} on {}, {}", scene.width, scene.height, gpu.adapter_summary(), surface.describe());
        let home = Orbit::of(&scene.camera);
        Ok(State {
            window,
            surface,
            gpu,
            renderer,
            presenter,
            home,
            orbit: home,
            drawn: home,
            mode: self.inputs.settings.estimator,
            view: View::Shaded,
            exposure_ev: self.inputs.tone_mapping.exposure_ev,
            cursor: None,
            dragging: false,
            ms_per_frame: None,
            frames_per_redraw: 1,
        })
    }

    /// Adds frames, draws the average into the window, saves the screenshot when it is due.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        let settings = self.inputs.settings;
        let target = match (&self.screenshot, state.view.is_deterministic()) {
            (_, true) => 1,
            (Some(_), false) => settings.frames,
            (None, false) => MAX_FRAMES,
        };
        state.accumulate(settings, self.inputs.scene, target)?;
        let frames = state.renderer.frames_accumulated();
        let Some(texture) = state.surface.acquire(&state.gpu)? else {
            // Nothing to draw into this time (timed out, occluded, reconfigured): try again.
            state.window.request_redraw();
            return Ok(());
        };
        let size = texture.size();
        texture.draw(&state.presenter, &state.renderer, state.exposure_ev)?;
        let due = frames >= target;
        if let (Some(path), true) = (&self.screenshot, due) {
            let rgb = texture.read_rgb8(&state.presenter, &state.renderer, state.exposure_ev)?;
            envmap::write_png_rgb8(path, size.0 as usize, size.1 as usize, &rgb)
                .map_err(|e| Error::Invalid(format!("writing {}: {e}", path.display())))?;
            self.shown = Some(format!("{}: {}", path.display(), state.title(frames, target)));
            texture.present(&state.gpu);
            self.finish(event_loop, Ok(()));
            return Ok(());
        }
        texture.present(&state.gpu);
        state.window.set_title(&state.title(frames, target));
        if !due {
            state.window.request_redraw();
        }
        Ok(())
    }

    fn finish(&mut self, event_loop: &ActiveEventLoop, outcome: Result<()>) {
        if self.outcome.is_none() {
            self.outcome = Some(outcome);
        }
        event_loop.exit();
    }
}

impl State {
    /// Brings the renderer to the current camera, then adds the frames of one redraw, up to
    /// `target` in all, timing them.
    fn accumulate(&mut self, settings: &Settings, scene: &render::Scene, target: u32) -> Result<()> {
        if self.orbit != self.drawn {
            let camera = self.orbit.camera(&scene.camera)?;
            self.renderer.set_camera(&camera)?;
            self.drawn = self.orbit;
        }
        let done = self.renderer.frames_accumulated();
        if done >= target {
            return Ok(());
        }
        let frames = self.frames_per_redraw.min(target - done);
        // The settings' frames size the fis estimator's footprints (`render::Settings::
        // filter_samples`), as they do for `--out`; the window goes on averaging past them.
        let settings = Settings { estimator: self.mode, ..*settings };
        let start = Instant::now();
        self.renderer.accumulate(&settings, self.view, frames)?;
        self.gpu.wait()?;
        let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(frames);
        self.ms_per_frame = Some(ms);
        self.frames_per_redraw = ((REDRAW_BUDGET_MS / ms.max(1e-3)).floor() as u32).clamp(1, MAX_FRAMES_PER_REDRAW);
        Ok(())
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        if self.surface.resize(&self.gpu, (size.width, size.height))? {
            self.window.request_redraw();
        }
        Ok(())
    }

    fn key(&mut self, event: &KeyEvent, material: &render::Material, lighting: &render::Lighting) -> KeyOutcome {
        if event.state != ElementState::Pressed {
            return KeyOutcome::Handled;
        }
        let restart = match &event.logical_key {
            Key::Named(NamedKey::Escape) => return KeyOutcome::Quit,
            Key::Character(c) => match c.as_str() {
                "q" | "Q" => return KeyOutcome::Quit,
                "1" => self.set_mode(Estimator::Reference, material, lighting),
                "2" => self.set_mode(Estimator::Fis, material, lighting),
                "3" => self.set_mode(Estimator::Prefiltered, material, lighting),
                "d" | "D" => {
                    let i = View::ALL.iter().position(|&v| v == self.view).unwrap_or(0);
                    self.view = View::ALL[(i + 1) % View::ALL.len()];
                    true
                }
                "+" | "=" => {
                    self.exposure_ev += EXPOSURE_STEP_EV;
                    false
                }
                "-" | "_" => {
                    self.exposure_ev -= EXPOSURE_STEP_EV;
                    false
                }
                "r" | "R" => {
                    // The next redraw draws the G-buffer again, which restarts.
                    self.orbit = self.home;
                    false
                }
                _ => return KeyOutcome::Handled,
            },
            _ => return KeyOutcome::Handled,
        };
        if restart {
            self.renderer.restart();
        }
        // The exposure only needs the average drawn again.
        self.window.request_redraw();
        KeyOutcome::Handled
    }

    /// Switches to `mode` unless the bake cannot render it; returns whether it changed (and the
    /// accumulation has to start again).
    fn set_mode(&mut self, mode: Estimator, material: &render::Material, lighting: &render::Lighting) -> bool {
        if mode == Estimator::Prefiltered && (lighting.layers.is_empty() || material.view_layers.is_empty()) {
            eprintln!(
                "prefiltered: the bake has no prefiltered layers or no view-layer table; staying in {}",
                self.mode.name()
            );
            return false;
        }
        let changed = mode != self.mode;
        self.mode = mode;
        changed
    }

    fn cursor_moved(&mut self, position: PhysicalPosition<f64>) {
        if let (true, Some(last)) = (self.dragging, self.cursor) {
            // Dragging right turns the mesh right (the eye moves the other way round); dragging
            // down shows more of its top.
            self.orbit.azimuth -= (position.x - last.x) as f32 * ORBIT_PER_PIXEL;
            self.orbit.elevation = (self.orbit.elevation + (position.y - last.y) as f32 * ORBIT_PER_PIXEL)
                .clamp(-Camera::MAX_ELEVATION, Camera::MAX_ELEVATION);
            self.window.request_redraw();
        }
        self.cursor = Some(position);
    }

    fn scroll(&mut self, delta: MouseScrollDelta) {
        let lines = match delta {
            MouseScrollDelta::LineDelta(_, y) => y,
            MouseScrollDelta::PixelDelta(p) => (p.y / PIXELS_PER_LINE) as f32,
        };
        // Scrolling up (positive) moves closer.
        let distance = self.orbit.distance * ZOOM_PER_LINE.powf(-lines);
        self.orbit.distance = distance.clamp(DISTANCE_RANGE.0, DISTANCE_RANGE.1);
        self.window.request_redraw();
    }

    /// The window's title: mode, frames, time per frame, view and exposure.
    fn title(&self, frames: u32, target: u32) -> String {
        let ms = self.ms_per_frame.map_or("-".to_string(), |ms| format!("{ms:.1}"));
        let done = if frames >= target { " (done)" } else { "" };
        let plural = if frames == 1 { "" } else { "s" };
        format!(
            "brdf-preview | {} | {frames} frame{plural}{done} | {ms} ms/frame | {} | {:+.1} EV",
            self.mode.name(),
            self.view.name(),
            self.exposure_ev
        )
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    fn check(vars: &[(&str, &str)], expect_display: bool) {
        let vars: HashMap<&str, OsString> = vars.iter().map(|&(k, v)| (k, OsString::from(v))).collect();
        let missing = missing_display(|name| vars.get(name).cloned());
        assert_eq!(missing.is_none(), expect_display, "{vars:?}: {missing:?}");
    }

    #[test]
    fn a_display_is_named_by_any_of_the_variables_winit_reads() {
        check(&[("DISPLAY", ":0")], true);
        check(&[("WAYLAND_DISPLAY", "wayland-0")], true);
        check(&[("WAYLAND_SOCKET", "3")], true);
        check(&[("DISPLAY", ""), ("WAYLAND_DISPLAY", "wayland-1")], true);
    }

    #[test]
    fn no_variable_or_empty_ones_name_no_display() {
        check(&[], false);
        check(&[("DISPLAY", ""), ("WAYLAND_DISPLAY", "")], false);
        check(&[("XDG_RUNTIME_DIR", "/tmp/xdg"), ("TERM", "xterm")], false);
    }

    #[test]
    fn the_error_says_what_is_missing_and_what_to_do_instead() {
        let reason = missing_display(|_| None).expect("no display");
        assert_eq!(
            no_display(reason).to_string(),
            "--window needs a display: neither DISPLAY nor WAYLAND_DISPLAY is set; render to a file with --out"
        );
    }

    #[test]
    fn winit_messages_lose_the_source_location() {
        assert_eq!(
            winit_message(&"os error at /home/u/.cargo/winit/src/mod.rs:788: Failed to open connection to X server"),
            "failed to open connection to X server"
        );
        assert_eq!(winit_message(&"X11 error"), "X11 error");
    }
}
