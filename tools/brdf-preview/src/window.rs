//! `--window`: the interactive previewer. A winit window shows the running average of the GPU
//! renderer (`gpu::preview::Renderer::accumulate`): every redraw adds frames (f = 0, 1, 2, ...)
//! until [`MAX_FRAMES`], and the present pass (`gpu::preview::Presenter`) tone maps the average
//! into the window like the pictures `--out` writes (`envmap::tonemap_rgb8`). The surface is a
//! plain 8-bit format where the adapter offers one, so that the pass writes the sRGB-encoded bytes
//! itself and the window shows the picture's bytes (up to a rare one-step rounding difference:
//! the GPU applies the exposure in f32); an sRGB-only surface encodes in hardware, within one
//! 8-bit step of them. `--window-screenshot` saves what the window shows and exits, for scripts.
//!
//! Controls: drag with the left button to orbit (azimuth, elevation), scroll to change the
//! distance, 1/2/3 for the reference, fis and prefiltered modes, D to cycle the views (shaded,
//! normals, the prefiltered layer per pixel, the sample slice per pixel; `gpu::preview::View`),
//! +/- for the exposure in half stops, R to reset the camera, Esc or Q to quit. A change of
//! camera, mode or view starts the accumulation again; the exposure only redraws.

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use gpu::preview::{Presenter, Renderer, View};
use render::{Camera, Mode, Settings};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

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

/// Redraws in a row that may get no surface texture (timeouts, a surface reconfigured or made
/// again) before the window gives up: a resize takes one or two; a surface that stays lost would
/// otherwise redraw forever.
const MAX_SKIPPED: u32 = 100;

/// Exposure change per key press, in stops.
const EXPOSURE_STEP_EV: f32 = 0.5;

const KEY_HELP: &str = "brdf-preview window: drag (left button) to orbit, scroll to zoom, 1/2/3 reference/fis/prefiltered, \
                        D cycles views (shaded, normals, prefiltered layer, sample slice), +/- exposure, R resets the \
                        camera, Esc/Q quits";

/// The window's options beside `--window`.
#[derive(Debug, clap::Args)]
pub struct Options {
    /// With --window: once --frames frames are accumulated (1 for a debug view), save what the
    /// window shows (PNG) and exit. For scripts and CI (e.g. under xvfb-run).
    #[arg(long, value_name = "FILE.png", requires = "window")]
    pub window_screenshot: Option<PathBuf>,
}

/// Opens a window showing the scene, rendered with the GPU renderer, until it is closed. Fails
/// with "--window needs a display: ...; render to a file with --out" where no window can open.
pub fn run(
    material: &render::Material,
    lighting: &render::Lighting,
    scene: &render::Scene,
    settings: &render::Settings,
    preview: &envmap::Preview,
    options: &Options,
) -> Result<ExitCode> {
    // Elsewhere (macOS, Windows) there is always a display to ask.
    if cfg!(all(unix, not(target_os = "macos")))
        && let Some(reason) = missing_display(|name| std::env::var_os(name))
    {
        return Err(no_display(reason));
    }
    let event_loop =
        EventLoop::new().map_err(|e| no_display(format!("opening the event loop: {}", winit_message(&e))))?;
    // wgpu wants the display the surfaces will be on (only GLES uses it; Vulkan ignores it).
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
        event_loop.owned_display_handle(),
    )));
    let mut app = App {
        inputs: Inputs { material, lighting, scene, settings, preview },
        screenshot: options.window_screenshot.clone(),
        instance,
        state: None,
        outcome: None,
    };
    eprintln!("{KEY_HELP}");
    event_loop.run_app(&mut app).map_err(|e| anyhow!("running the window's event loop: {e}"))?;
    match app.outcome {
        Some(Err(e)) => Err(e),
        Some(Ok(())) | None => Ok(ExitCode::SUCCESS),
    }
}

/// The error of a machine where no window can open.
fn no_display(reason: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("--window needs a display: {reason}; render to a file with --out")
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
    preview: &'a envmap::Preview,
}

struct App<'a> {
    inputs: Inputs<'a>,
    screenshot: Option<PathBuf>,
    instance: wgpu::Instance,
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
    instance: wgpu::Instance,
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: gpu::Gpu,
    renderer: Renderer,
    presenter: Presenter,
    home: Orbit,
    orbit: Orbit,
    /// The orbit the renderer's G-buffer was drawn for.
    drawn: Orbit,
    mode: Mode,
    view: View,
    exposure_ev: f32,
    /// The cursor's last position, and whether the left button drags it.
    cursor: Option<PhysicalPosition<f64>>,
    dragging: bool,
    /// The last measured time per frame, and how many frames a redraw adds.
    ms_per_frame: Option<f64>,
    frames_per_redraw: u32,
    /// Redraws in a row that got no surface texture.
    skipped: u32,
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
        let surface = self.instance.create_surface(window.clone()).context("creating the window's surface")?;
        let gpu = gpu::Gpu::for_surface(&self.instance, &surface)?;
        let caps = surface.get_capabilities(gpu.adapter());
        let format = surface_format(&caps.formats).ok_or_else(|| {
            anyhow!(
                "the window's surface offers none of the 8-bit RGBA or BGRA formats the previewer draws: {:?}",
                caps.formats
            )
        })?;
        // A screenshot reads the surface texture itself where the surface allows it.
        let usage = if self.screenshot.is_some() && caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC
        } else {
            wgpu::TextureUsages::RENDER_ATTACHMENT
        };
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: Default::default(),
            width: size.width.max(1),
            height: size.height.max(1),
            // The one mode every surface supports (lavapipe presents to Xvfb with it).
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
                wgpu::CompositeAlphaMode::Opaque
            } else {
                wgpu::CompositeAlphaMode::Auto
            },
            view_formats: vec![],
        };
        gpu.configure_surface(&surface, &config)?;
        let renderer = Renderer::new(&gpu, scene, self.inputs.material, self.inputs.lighting)?;
        let presenter = Presenter::new(&gpu, format)?;
        let read = if usage.contains(wgpu::TextureUsages::COPY_SRC) { "the surface" } else { "an offscreen copy" };
        eprintln!(
            "window: {}x{} on {}, surface {format:?}{}",
            scene.width,
            scene.height,
            gpu.adapter_summary(),
            if self.screenshot.is_some() { format!(", screenshot read from {read}") } else { String::new() }
        );
        let home = Orbit::of(&scene.camera);
        Ok(State {
            instance: self.instance.clone(),
            window,
            surface,
            config,
            gpu,
            renderer,
            presenter,
            home,
            orbit: home,
            drawn: home,
            mode: self.inputs.settings.mode,
            view: View::Shaded,
            exposure_ev: self.inputs.preview.exposure_ev,
            cursor: None,
            dragging: false,
            ms_per_frame: None,
            frames_per_redraw: 1,
            skipped: 0,
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
        let Some(texture) = state.acquire()? else {
            // Nothing to draw into this time (timed out, occluded, reconfigured): try again.
            state.window.request_redraw();
            return Ok(());
        };
        let size = (texture.texture.width(), texture.texture.height());
        let view = texture.texture.create_view(&Default::default());
        state.presenter.draw(&state.renderer, &view, size, state.exposure_ev)?;
        let due = frames >= target;
        if let (Some(path), true) = (&self.screenshot, due) {
            let rgb = if state.config.usage.contains(wgpu::TextureUsages::COPY_SRC) {
                state.presenter.read_rgb8(&texture.texture)?
            } else {
                state.presenter.draw_rgb8(&state.renderer, size, state.exposure_ev)?
            };
            envmap::write_png_rgb8(path, size.0 as usize, size.1 as usize, &rgb)
                .with_context(|| format!("writing {}", path.display()))?;
            cli::outln!("{}: {}", path.display(), state.title(frames, target));
            state.gpu.queue().present(texture);
            self.finish(event_loop, Ok(()));
            return Ok(());
        }
        state.gpu.queue().present(texture);
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
        let settings = Settings { mode: self.mode, frames, ..*settings };
        let start = Instant::now();
        self.renderer.accumulate(&settings, self.view)?;
        self.gpu.device().poll(wgpu::PollType::wait_indefinitely())?;
        let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(frames);
        self.ms_per_frame = Some(ms);
        self.frames_per_redraw = ((REDRAW_BUDGET_MS / ms.max(1e-3)).floor() as u32).clamp(1, MAX_FRAMES_PER_REDRAW);
        Ok(())
    }

    /// The surface's next texture, or `None` where this redraw has to be skipped; reconfigures
    /// an outdated surface and makes a lost one again, and gives up after [`MAX_SKIPPED`] skips
    /// in a row.
    fn acquire(&mut self) -> Result<Option<wgpu::SurfaceTexture>> {
        let texture = self.try_acquire()?;
        self.skipped = if texture.is_some() { 0 } else { self.skipped + 1 };
        if self.skipped > MAX_SKIPPED {
            bail!("the window's surface gave no texture to draw into {MAX_SKIPPED} times in a row");
        }
        Ok(texture)
    }

    fn try_acquire(&mut self) -> Result<Option<wgpu::SurfaceTexture>> {
        use wgpu::CurrentSurfaceTexture as Current;
        match self.surface.get_current_texture() {
            Current::Success(texture) => Ok(Some(texture)),
            Current::Timeout | Current::Occluded => Ok(None),
            // The surface changed (a resize under way): the texture must go before configuring.
            Current::Suboptimal(texture) => {
                drop(texture);
                self.reconfigure()?;
                Ok(None)
            }
            Current::Outdated => {
                self.reconfigure()?;
                Ok(None)
            }
            Current::Lost => {
                self.surface =
                    self.instance.create_surface(self.window.clone()).context("creating the window's surface again")?;
                self.reconfigure()?;
                Ok(None)
            }
            Current::Validation => Err(anyhow!("the window's surface reported a validation error")),
        }
    }

    /// Configures the surface again for the window's size as the last resize reported it (not
    /// asked of the window, which winit cannot answer for a window already gone).
    fn reconfigure(&mut self) -> Result<()> {
        Ok(self.gpu.configure_surface(&self.surface, &self.config)?)
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        // A minimized window reports 0 x 0, which no surface takes: keep the last size.
        if size.width > 0 && size.height > 0 {
            self.config.width = size.width;
            self.config.height = size.height;
            self.reconfigure()?;
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
                "1" => self.set_mode(Mode::Reference, material, lighting),
                "2" => self.set_mode(Mode::Fis, material, lighting),
                "3" => self.set_mode(Mode::Prefiltered, material, lighting),
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
    fn set_mode(&mut self, mode: Mode, material: &render::Material, lighting: &render::Lighting) -> bool {
        if mode == Mode::Prefiltered && (lighting.layers.is_empty() || material.view_layers.is_empty()) {
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

/// The surface format to draw: a plain 8-bit one where offered, into which the present pass
/// writes the picture's sRGB-encoded bytes itself; else an sRGB one, which encodes in hardware.
fn surface_format(offered: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat as F;
    [F::Bgra8Unorm, F::Rgba8Unorm, F::Bgra8UnormSrgb, F::Rgba8UnormSrgb].into_iter().find(|f| offered.contains(f))
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

    #[test]
    fn a_plain_surface_format_is_preferred_to_an_srgb_one() {
        use wgpu::TextureFormat as F;
        assert_eq!(surface_format(&[F::Bgra8UnormSrgb, F::Bgra8Unorm]), Some(F::Bgra8Unorm));
        assert_eq!(surface_format(&[F::Rgba16Float, F::Rgba8UnormSrgb]), Some(F::Rgba8UnormSrgb));
        assert_eq!(surface_format(&[F::Rgb10a2Unorm]), None);
    }
}
