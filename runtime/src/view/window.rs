//! Presenting a session in a window: a winit window with a wgpu surface, on the device that
//! renders the kernel (the adapter is the one that can present to the surface), or, where no
//! adapter can present, softbuffer and the CPU renderer ([`super::present`]); the parameter
//! panel beside the image ([`super::panel`]) and `--change`'s scripted changes through it; the
//! mouse and keys that move the camera, the title line, and the screenshots of `--screenshot`
//! and `--screenshot-dir`, read back from what is presented.

use super::compile::Waker;
use super::panel::Panel;
use super::present::{self, wgpu_presenter, Overlay, Presenter, SoftPresenter};
use super::session::{Device, Outcome, Session};
use super::watch::Watch;
use super::{widgets, Run};
use crate::backend::Backend;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Events sent to the event loop from other threads.
#[derive(Debug)]
enum UserEvent {
    /// The watcher saw these paths change, the first of them at this time.
    Files(Vec<PathBuf>, std::time::SystemTime),
    /// A kernel's pipeline compiling on another thread is ready (or failed).
    Compiled,
}

/// Runs the viewer in a window until it is closed (or `control` says to stop).
pub fn run(run: Run) -> ExitCode {
    let event_loop = match EventLoop::<UserEvent>::with_user_event().build() {
        Ok(l) => l,
        Err(e) => {
            eprintln!(
                "error: cannot open a window: {e}; `sdfc view --headless` runs the viewer without one"
            );
            return ExitCode::from(2);
        }
    };
    event_loop.set_control_flow(ControlFlow::Wait);
    let mut app = App {
        proxy: event_loop.create_proxy(),
        run,
        state: None,
        exit: ExitCode::SUCCESS,
    };
    if let Err(e) = event_loop.run_app(&mut app) {
        eprintln!("error: the window's event loop failed: {e}");
        return ExitCode::from(2);
    }
    let code = app.exit;
    // The window, its surface and the session are not dropped: a kernel may still be
    // compiling on another thread, and dropping the surface waits for the device's queue,
    // which that compile may hold for seconds on lavapipe. The process ends next
    // (`commands::view`).
    std::mem::forget(app);
    code
}

struct App {
    proxy: EventLoopProxy<UserEvent>,
    run: Run,
    state: Option<State>,
    exit: ExitCode,
}

impl std::fmt::Debug for App {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("App").finish_non_exhaustive()
    }
}

/// The open window and what runs in it.
struct State {
    window: Arc<Window>,
    presenter: Presenter,
    session: Session,
    _watch: Option<Watch>,
    stats: bool,
    title: String,
    cursor: Option<PhysicalPosition<f64>>,
    left: bool,
    middle: bool,
    shift: bool,
    /// Frames presented.
    frames: u64,
    /// The load whose settled image is still to be written to `--screenshot-dir`.
    shot_for: Option<u32>,
    /// Whether the image on show has changed since it was uploaded.
    dirty: bool,
    /// The parameter panel (where wgpu presents).
    panel: Option<Panel>,
    /// The panel's width while it is on show, as the layout last took it.
    panel_width: Option<u32>,
    /// `--change`'s changes still to make, each once the image before has settled.
    changes: VecDeque<(String, String)>,
}

/// Why the window did not start.
#[derive(Debug, thiserror::Error)]
enum StartError {
    /// No window could be opened.
    #[error("cannot open a window: {0}")]
    Window(winit::error::OsError),
    /// `--backend wgpu`, and wgpu cannot present to the window.
    #[error("{0}: install a Vulkan driver (on Linux without a GPU, Mesa's lavapipe: `apt-get install mesa-vulkan-drivers`), or use --backend cpu")]
    Wgpu(present::Error),
    /// Neither wgpu nor softbuffer can draw in the window.
    #[error(transparent)]
    Soft(present::Error),
}

impl App {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<State, StartError> {
        let (w, h) = Session::initial_size(&self.run.file, &self.run.options);
        let attributes = Window::default_attributes()
            .with_title(format!("sdfc view: {}", self.run.file.display()))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(StartError::Window)?,
        );
        let (device, presenter) = match wgpu_presenter(event_loop, &window) {
            Ok((gpu, presenter)) => {
                let device = match self.run.options.job.backend {
                    Backend::Cpu => Device::Cpu,
                    Backend::Wgpu => Device::Wgpu(gpu.clone()),
                    // Like `sdfc render`, auto takes a hardware GPU, else the CPU renderer.
                    _ if gpu.is_cpu() => Device::Cpu,
                    _ => Device::Wgpu(gpu.clone()),
                };
                eprintln!(
                    "view: rendering on {} ({}), presenting through wgpu on {}",
                    device.name(),
                    device.describe(),
                    gpu.describe()
                );
                (device, Presenter::Gpu(Box::new(presenter)))
            }
            Err(e) if self.run.options.job.backend == Backend::Wgpu => {
                return Err(StartError::Wgpu(e));
            }
            Err(msg) => {
                let presenter =
                    SoftPresenter::new(event_loop, &window).map_err(StartError::Soft)?;
                eprintln!(
                    "view: {msg}; rendering on the CPU ({}) and presenting with softbuffer",
                    Device::Cpu.describe()
                );
                (Device::Cpu, Presenter::Soft(presenter))
            }
        };
        let size = window.inner_size();
        let mut session = Session::new(self.run.file.clone(), self.run.options.clone(), device);
        session.set_size(size.width.max(1), size.height.max(1));
        session.want_steps(self.run.control.stats);
        let proxy = std::sync::Mutex::new(self.proxy.clone());
        session.set_waker(Waker::new(move || {
            let proxy = proxy.lock().unwrap_or_else(|e| e.into_inner());
            let _ = proxy.send_event(UserEvent::Compiled);
        }));
        let outcome = session.load();
        let mut panel = match (&presenter, session.device()) {
            (Presenter::Gpu(p), _) => Some(Panel::new(&window, p.gpu(), p.format())),
            (Presenter::Soft(_), _) => None,
        };
        if let Some(panel) = panel.as_mut() {
            panel.follow(session.params());
            // The panel goes beside the image: the window widens by it, the image keeps its
            // size.
            if let Some(extra) = panel.width(&window) {
                let _ =
                    window.request_inner_size(PhysicalSize::new(size.width + extra, size.height));
            }
        }
        let proxy = self.proxy.clone();
        let watch = match Watch::new(move |paths, seen| {
            let _ = proxy.send_event(UserEvent::Files(paths, seen));
        }) {
            Ok(mut w) => {
                for problem in w.add(session.files()) {
                    eprintln!("warning: {problem}");
                }
                Some(w)
            }
            Err(msg) => {
                eprintln!("warning: {msg}; the scene will not be reloaded when it changes");
                None
            }
        };
        Ok(State {
            window,
            presenter,
            session,
            _watch: watch,
            stats: self.run.control.stats,
            title: String::new(),
            cursor: None,
            left: false,
            middle: false,
            shift: false,
            frames: 0,
            shot_for: Some(outcome.number),
            dirty: true,
            panel,
            panel_width: None,
            changes: self.run.control.changes.iter().cloned().collect(),
        })
    }

    fn finish(&mut self, event_loop: &ActiveEventLoop, code: ExitCode) {
        self.exit = code;
        event_loop.exit();
    }

    /// Renders (when the session wants a frame), presents, and writes the screenshots due.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let Some(st) = self.state.as_mut() else {
            return;
        };
        // While a kernel compiles with nothing new to show, nothing is drawn: the window keeps
        // the picture it shows. The device's queue is left to the compile, whose first
        // dispatch is where lavapipe compiles the kernel (tens of seconds for a large one);
        // work queued behind it would hold the event loop until it ends.
        if st.session.compiling() && !st.session.wants_frame() {
            return;
        }
        // The panel follows the scene on show (a load may add, remove or change parameters);
        // the image's part of the window follows the panel.
        if let Some(panel) = st.panel.as_mut() {
            panel.follow(st.session.params());
        }
        st.layout();
        match st.session.frame() {
            Ok(Some(_)) => st.dirty = true,
            Ok(None) => {}
            Err(msg) => eprintln!("error: {msg}"),
        }
        let (changes, again) = match st.panel.as_mut() {
            Some(panel) => panel.run(&st.window),
            None => (Vec::new(), false),
        };
        // The panel's changes load the scene with their values (each a load, with its
        // screenshot in `--screenshot-dir`); the frame drawn now shows the panel with them
        // over the image before, and the next frames the new scene.
        for (name, value) in changes {
            st.shot_for = Some(st.session.set_param(&name, &value).number);
        }
        if again {
            st.window.request_redraw();
        }
        // A frame of the GPU is on show in its texture, where the kernel's frames were
        // accumulated; the CPU renderer's image is uploaded.
        if let Some((texture, number)) = st.session.texture() {
            st.presenter.show(texture, number);
        } else if st.dirty {
            if let Some(image) = st.session.host_image() {
                st.presenter.upload(image);
            }
        }
        st.dirty = false;
        let control = &self.run.control;
        let settled = st.session.settled();
        let reload_shot = match (st.shot_for, &control.screenshot_dir) {
            (Some(k), Some(dir)) if settled => Some((k, dir.join(format!("reload-{k}.png")))),
            _ => None,
        };
        let last = control.frames.is_some_and(|n| st.frames + 1 >= n);
        let final_shot = control.screenshot.clone().filter(|_| last);
        let wanted: Vec<PathBuf> = reload_shot
            .iter()
            .map(|(_, p)| p.clone())
            .chain(final_shot)
            .collect();
        let overlay = st.panel.as_mut().map(|p| p as &mut dyn Overlay);
        match st.presenter.present(&wanted, overlay) {
            Ok(true) => {
                st.frames += 1;
                st.session.presented();
            }
            Ok(false) => {
                st.window.request_redraw();
                return;
            }
            Err(msg) => {
                eprintln!("error: {msg}");
                return self.finish(event_loop, ExitCode::from(1));
            }
        }
        for path in &wanted {
            eprintln!("view: wrote {}", path.display());
        }
        if let Some((k, _)) = reload_shot {
            st.shot_for = None;
            if control.exit_after_reloads == Some(k) {
                return self.finish(event_loop, ExitCode::SUCCESS);
            }
            // `--change`'s next change, now that the image before it has settled.
            if let Some((name, text)) = st.changes.pop_front() {
                match st.change(&name, &text) {
                    Ok(outcome) => st.shot_for = Some(outcome.number),
                    Err(msg) => {
                        eprintln!("error: --change {name}={text}: {msg}");
                        return self.finish(event_loop, ExitCode::from(2));
                    }
                }
                st.window.request_redraw();
            }
        }
        if last {
            self.finish(event_loop, ExitCode::SUCCESS);
        }
    }
}

impl State {
    /// Gives the image the part of the window the panel leaves it (all of it while the panel
    /// is hidden or the scene has no parameters): the session renders at that size.
    fn layout(&mut self) {
        let width = self.panel.as_ref().and_then(|p| p.width(&self.window));
        if width == self.panel_width {
            return;
        }
        self.panel_width = width;
        self.fit();
    }

    /// Sizes the session's image and the presenter's view to the window less the panel.
    fn fit(&mut self) {
        let size = self.window.inner_size();
        let view = size
            .width
            .saturating_sub(self.panel_width.unwrap_or(0))
            .max(1);
        self.presenter
            .set_view_width(self.panel_width.map(|_| view));
        self.session.set_size(view, size.height.max(1));
        self.window.request_redraw();
    }

    /// `--change NAME=VALUE`: sets the parameter's control to the value as its widget would
    /// be set, and gives the session the value it stands for.
    fn change(&mut self, name: &str, text: &str) -> Result<Outcome, widgets::ChangeError> {
        let value = match self.panel.as_mut() {
            Some(panel) => {
                panel.follow(self.session.params());
                panel.change(name, text)?
            }
            None => widgets::change(self.session.params(), name, text)?,
        };
        Ok(self.session.set_param(name, &value))
    }
}

impl ApplicationHandler<UserEvent> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(st) => {
                st.window.request_redraw();
                self.state = Some(st);
            }
            Err(msg) => {
                eprintln!("error: {msg}");
                self.finish(event_loop, ExitCode::from(2));
            }
        }
    }

    fn user_event(&mut self, _: &ActiveEventLoop, event: UserEvent) {
        let Some(st) = self.state.as_mut() else {
            return;
        };
        let (paths, seen) = match event {
            UserEvent::Files(paths, seen) => (paths, seen),
            UserEvent::Compiled => {
                st.window.request_redraw();
                return;
            }
        };
        if st.session.needs_reload(&paths) {
            // The load reads, checks, lowers and prepares here (milliseconds); a new kernel's
            // pipeline compiles on another thread, and the loop goes on meanwhile.
            let outcome = st.session.load_edited(Some(seen));
            if let Some(w) = st._watch.as_mut() {
                for problem in w.add(st.session.files()) {
                    eprintln!("warning: {problem}");
                }
            }
            st.shot_for = Some(outcome.number);
            st.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(st) = self.state.as_mut() else {
            return;
        };
        // The panel sees every event first; what it takes (the pointer over it or dragging
        // one of its controls, the keys while a text field has them) moves no camera.
        let (mut pointer, mut keys) = (false, false);
        if let Some(panel) = st.panel.as_mut() {
            if panel.on_event(&st.window, &event) {
                st.window.request_redraw();
            }
            (pointer, keys) = (panel.wants_pointer(), panel.wants_keys());
        }
        match event {
            WindowEvent::CloseRequested => self.finish(event_loop, ExitCode::SUCCESS),
            WindowEvent::Resized(size) => {
                st.presenter.resize(size.width, size.height);
                st.fit();
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            WindowEvent::ModifiersChanged(m) => st.shift = m.state().shift_key(),
            WindowEvent::MouseInput { state, button, .. } => {
                // A press on the panel is the panel's; a release ends any drag.
                let down = state == ElementState::Pressed && !pointer;
                match button {
                    MouseButton::Left => st.left = down,
                    MouseButton::Middle => st.middle = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some(old) = st.cursor {
                    let (dx, dy) = (position.x - old.x, position.y - old.y);
                    if st.middle || (st.left && st.shift) {
                        st.session.pan(dx, dy);
                    } else if st.left {
                        st.session.rotate(dx, dy);
                    }
                    if st.left || st.middle {
                        st.window.request_redraw();
                    }
                }
                st.cursor = Some(position);
            }
            WindowEvent::CursorLeft { .. } => st.cursor = None,
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                if !pointer {
                    st.session.zoom(lines);
                    st.window.request_redraw();
                }
            }
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed && !keys =>
            {
                match event.logical_key.as_ref() {
                    Key::Character(c) if c.eq_ignore_ascii_case("p") => {
                        if let Some(panel) = st.panel.as_mut() {
                            panel.visible = !panel.visible;
                            st.window.request_redraw();
                        }
                    }
                    Key::Character(c) if c.eq_ignore_ascii_case("r") => {
                        st.session.reset_camera();
                        st.window.request_redraw();
                    }
                    Key::Character(c) if c.eq_ignore_ascii_case("s") => {
                        st.stats = !st.stats;
                        st.session.want_steps(st.stats);
                    }
                    Key::Named(NamedKey::Tab) => {
                        st.stats = !st.stats;
                        st.session.want_steps(st.stats);
                    }
                    Key::Named(NamedKey::Space) => {
                        st.session.toggle_pause();
                        st.window.request_redraw();
                    }
                    Key::Named(NamedKey::Escape) => self.finish(event_loop, ExitCode::SUCCESS),
                    Key::Character(c) if c.eq_ignore_ascii_case("q") => {
                        self.finish(event_loop, ExitCode::SUCCESS)
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(st) = self.state.as_mut() else {
            return;
        };
        // While a new scene waits its grace period for its specialised kernel, the loop goes
        // on handling events and wakes at the period's end (a frame of the interpreted kernel
        // may then be due); the compile's end wakes it sooner ([`UserEvent::Compiled`]).
        event_loop.set_control_flow(match st.session.grace_deadline() {
            Some(end) => ControlFlow::WaitUntil(end),
            None => ControlFlow::Wait,
        });
        let title = st.session.title(st.stats);
        if title != st.title {
            st.window.set_title(&title);
            st.title = title;
        }
        // While a kernel compiles with nothing to render, the loop sleeps until the compile's
        // end wakes it ([`UserEvent::Compiled`]): no frame is counted or shot meanwhile.
        let control = &self.run.control;
        let waiting = st.session.compiling() && !st.session.wants_frame();
        if st.session.wants_frame()
            || (!waiting && control.frames.is_some())
            || (!waiting && st.shot_for.is_some() && control.screenshot_dir.is_some())
        {
            st.window.request_redraw();
        }
    }
}
