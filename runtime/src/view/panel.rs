//! The viewer's parameter panel: an egui side panel drawn into the window's wgpu surface, on
//! the right of the image, with a control for each of the scene's parameters (a slider, a
//! checkbox, a list, a number or text field: [`super::widgets`]), its name, description and
//! the values it accepts. A control's change is handed to the window, which gives the session
//! the new value ([`super::session::Session::set_param`]). The panel is shown only for a scene
//! with parameters, and P hides and shows it. Text is DejaVu Sans, as in `sdfc pareto`'s charts.

use super::present::Overlay;
use super::widgets::{self, Control, Kind, Raw};
use crate::gpu::Gpu;
use sdfc_compiler::{ParamValue, Parameter};
use std::sync::Arc;
use winit::event::WindowEvent;
use winit::window::Window;

/// The panel's width, in egui points (pixels at a scale factor of 1).
pub const WIDTH: f32 = 260.0;

/// The panel: egui's context and its window input, the renderer that draws it with wgpu, and
/// the controls of the scene on show.
pub struct Panel {
    ctx: egui::Context,
    input: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    /// Whether the user shows it (P); it is drawn only when the scene has parameters too.
    pub visible: bool,
    /// The parameters the controls were made from.
    source: Vec<Parameter>,
    controls: Vec<Control>,
    /// What the text fields hold while they are edited (applied when the field is left).
    texts: Vec<String>,
    /// What the last pass drew, to be drawn by [`Overlay::draw`].
    frame: Option<Frame>,
}

/// One pass's drawing.
struct Frame {
    primitives: Vec<egui::ClippedPrimitive>,
    textures: egui::TexturesDelta,
    pixels_per_point: f32,
}

impl std::fmt::Debug for Panel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Panel")
            .field("visible", &self.visible)
            .field("controls", &self.controls)
            .finish_non_exhaustive()
    }
}

impl Panel {
    /// A panel for `window`, drawn on `gpu` into a surface of `format`.
    pub fn new(window: &Window, gpu: &Gpu, format: wgpu::TextureFormat) -> Panel {
        let ctx = egui::Context::default();
        let mut fonts = egui::FontDefinitions::empty();
        fonts.font_data.insert(
            "DejaVu Sans".into(),
            Arc::new(egui::FontData::from_static(dejavu::sans::regular())),
        );
        for family in [egui::FontFamily::Proportional, egui::FontFamily::Monospace] {
            fonts.families.insert(family, vec!["DejaVu Sans".into()]);
        }
        ctx.set_fonts(fonts);
        ctx.set_visuals(egui::Visuals::dark());
        let max = gpu.device().limits().max_texture_dimension_2d as usize;
        let input = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(max),
        );
        let renderer =
            egui_wgpu::Renderer::new(gpu.device(), format, egui_wgpu::RendererOptions::default());
        Panel {
            ctx,
            input,
            renderer,
            visible: true,
            source: Vec::new(),
            controls: Vec::new(),
            texts: Vec::new(),
            frame: None,
        }
    }

    /// Whether the panel is on show: shown by the user and the scene has parameters.
    pub fn shown(&self) -> bool {
        self.visible && !self.controls.is_empty()
    }

    /// The panel's width in the window's pixels, while it is on show.
    pub fn width(&self, window: &Window) -> Option<u32> {
        self.shown()
            .then(|| (WIDTH * window.scale_factor() as f32).ceil() as u32)
    }

    /// Makes the controls those of `params` (the scene on show), when they changed: a new
    /// load, or a value set.
    pub fn follow(&mut self, params: &[Parameter]) {
        if params == self.source.as_slice() {
            return;
        }
        self.source = params.to_vec();
        self.controls = params.iter().map(Control::of).collect();
        self.texts = self
            .controls
            .iter()
            .map(|c| match &c.value {
                ParamValue::Str(s) => s.clone(),
                _ => String::new(),
            })
            .collect();
    }

    /// Hands a window event to egui; returns whether it wants the panel drawn again.
    pub fn on_event(&mut self, window: &Window, event: &WindowEvent) -> bool {
        self.input.on_window_event(window, event).repaint
    }

    /// Whether the pointer belongs to the panel: over it, or dragging one of its controls
    /// (egui's `wants_pointer_input`); the camera then does not move.
    pub fn wants_pointer(&self) -> bool {
        self.shown() && self.ctx.egui_wants_pointer_input()
    }

    /// Whether a text field has the keys (the viewer's keys then do nothing). A slider or
    /// checkbox that has the focus after a click leaves them to the viewer.
    pub fn wants_keys(&self) -> bool {
        self.shown() && self.ctx.text_edit_focused()
    }

    /// Runs one pass of the panel's interface for the frame to be presented; returns the
    /// changes made to its controls (a parameter's name and its new value, one it accepts) and
    /// whether egui asks to be drawn again at once (a control still moving).
    pub fn run(&mut self, window: &Window) -> (Vec<(String, ParamValue)>, bool) {
        if !self.shown() {
            self.frame = None;
            return (Vec::new(), false);
        }
        let raw = self.input.take_egui_input(window);
        let mut changes = Vec::new();
        let controls = &mut self.controls;
        let texts = &mut self.texts;
        let out = self.ctx.run_ui(raw, |ui| {
            egui::Panel::right("sdfc parameters")
                .resizable(false)
                .exact_size(WIDTH)
                .show(ui, |ui| {
                    ui.add_space(6.0);
                    ui.heading("Parameters");
                    ui.weak("P hides this panel");
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        for (c, text) in controls.iter_mut().zip(texts.iter_mut()) {
                            ui.separator();
                            if let Some(v) = control(ui, c, text) {
                                changes.push((c.name.clone(), v));
                            }
                        }
                    });
                });
        });
        self.input
            .handle_platform_output(window, out.platform_output);
        let again = out
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        let primitives = self.ctx.tessellate(out.shapes, out.pixels_per_point);
        self.frame = Some(Frame {
            primitives,
            textures: out.textures_delta,
            pixels_per_point: out.pixels_per_point,
        });
        (changes, again)
    }

    /// Sets the control of the parameter `name` to the value written `text`, as its widget
    /// would be set (`--change NAME=VALUE`): the value it stands for, within the range and on
    /// the step, which the caller gives the session.
    pub fn change(&mut self, name: &str, text: &str) -> Result<ParamValue, widgets::ChangeError> {
        let i = self
            .controls
            .iter()
            .position(|c| c.name == name)
            .ok_or_else(|| widgets::unknown(&self.source, name))?;
        let value = widgets::value_from_text(&self.controls[i], text)?;
        self.controls[i].value = value.clone();
        if let ParamValue::Str(s) = &value {
            self.texts[i] = s.clone();
        }
        Ok(value)
    }
}

/// Draws one parameter's name, range, description and widget; returns its new value when the
/// user changed it.
fn control(ui: &mut egui::Ui, c: &mut Control, text: &mut String) -> Option<ParamValue> {
    ui.horizontal(|ui| {
        ui.strong(&c.name);
        if !matches!(c.kind, Kind::Check | Kind::Text) {
            ui.weak(&c.accepts);
        }
    });
    if !c.doc.is_empty() {
        ui.label(&c.doc);
    }
    let raw = match (&c.kind, c.raw()) {
        (&Kind::Slider { lo, hi, step, int }, Raw::Number(mut x)) => {
            ui.spacing_mut().slider_width = WIDTH - 100.0;
            let mut slider =
                egui::Slider::new(&mut x, lo..=hi).clamping(egui::SliderClamping::Always);
            if int {
                slider = slider.integer();
            } else if let Some(d) = widgets::decimals(lo, step) {
                slider = slider.fixed_decimals(d);
            }
            ui.add(slider).changed().then_some(Raw::Number(x))
        }
        (&Kind::Number { int }, Raw::Number(mut x)) => {
            let speed = if int { 0.1 } else { (x.abs() * 0.01).max(0.01) };
            let field = egui::DragValue::new(&mut x).speed(speed);
            ui.add(field).changed().then_some(Raw::Number(x))
        }
        (Kind::Check, Raw::Bool(mut b)) => {
            let label = if b { "on" } else { "off" };
            ui.checkbox(&mut b, label).changed().then_some(Raw::Bool(b))
        }
        (Kind::Choice(choices), Raw::Text(s)) => {
            let mut chosen = s.clone();
            egui::ComboBox::from_id_salt(&c.name)
                .selected_text(&chosen)
                .width(WIDTH - 40.0)
                .show_ui(ui, |ui| {
                    for choice in choices {
                        ui.selectable_value(&mut chosen, choice.clone(), choice);
                    }
                });
            (chosen != s).then_some(Raw::Text(chosen))
        }
        (Kind::Text, Raw::Text(_)) => {
            let field = ui.text_edit_singleline(text);
            field.lost_focus().then(|| Raw::Text(text.clone()))
        }
        _ => None,
    };
    raw.and_then(|r| c.set(&r))
}

impl Overlay for Panel {
    fn draw(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let Some(frame) = self.frame.as_mut() else {
            return;
        };
        let (device, queue) = (gpu.device(), gpu.queue());
        // Set once: a second draw of the same pass (a screenshot drawn again) finds them set.
        for (id, deltas) in std::mem::take(&mut frame.textures.set) {
            for delta in &deltas {
                self.renderer.update_texture(device, queue, id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: frame.pixels_per_point,
        };
        let extra =
            self.renderer
                .update_buffers(device, queue, encoder, &frame.primitives, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sdfc view panel"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let mut pass = pass.forget_lifetime();
        self.renderer.render(&mut pass, &frame.primitives, &screen);
        drop(pass);
        for id in std::mem::take(&mut frame.textures.free) {
            self.renderer.free_texture(&id);
        }
    }
}
