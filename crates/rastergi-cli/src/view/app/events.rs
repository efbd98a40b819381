//! The viewer's window events: start-up, the build thread's answers, input and redraws, and the
//! idle loop that iterates between them.

use super::*;

impl ApplicationHandler<UserEvent> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title(format!("rastergi - {}", self.scene_name))
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => return self.fail(event_loop, anyhow!("cannot open a window: {e}")),
        };
        let size = window.inner_size();
        if size.width > 0 && size.height > 0 {
            self.size = (size.width, size.height);
        }
        let display = event_loop.owned_display_handle();
        match DisplayTarget::open(&self.gpu_options, display, window.clone(), self.size.0, self.size.1) {
            Ok((gpu, surface)) => {
                let ctx = egui::Context::default();
                let max_texture_side = gpu.device.limits().max_texture_dimension_2d as usize;
                let input = egui_winit::State::new(
                    ctx.clone(),
                    egui::ViewportId::ROOT,
                    &window,
                    Some(window.scale_factor() as f32),
                    window.theme(),
                    Some(max_texture_side),
                );
                let painter = PanelPainter::new(&gpu.device, surface.format());
                self.panel = Some(Panel { ctx, input, painter, state: PanelState::default() });
                self.gpu = Some(gpu);
                self.surface = Some(surface);
            }
            Err(e) => return self.fail(event_loop, e.into()),
        }
        self.window = Some(window);
        self.start_build(None);
        self.redraw();
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, event: UserEvent) {
        let UserEvent::Built { generation, result } = event;
        if self.building != Some(generation) {
            return;
        }
        self.building = None;
        match result {
            Ok((active, build, opened)) => {
                self.status.clear();
                if let Some(o) = opened {
                    log::info!("opened {}: {} triangles", o.name, o.scene.triangles.len());
                    self.controls.set_home(CameraControl::new(&o.scene.camera, &o.scene.bounds()));
                    debug_assert_eq!(self.controls.camera.camera(), o.scene.camera, "a stable camera");
                    (self.controls.photons, self.controls.grid) = (o.photons, o.grid);
                    (self.controls.sun, self.controls.env_scale) = (o.sun, o.env_scale);
                    (self.scene_name, self.scene, self.scene_id) = (o.name, o.scene, build.scene);
                    self.title_at = Instant::now() - Duration::from_secs(1);
                }
                self.measured = Measured::default();
                // The denoiser (enabled by the build where asked) is taken up by sync_denoiser.
                let mut view = Interactive::new(active, self.controls.show, self.controls.exposure);
                view.set_frame_budget(self.frame_budget);
                self.renderer = Some((view, build));
                if let Some(run) = &mut self.script {
                    run.last = Instant::now();
                }
            }
            Err(e) if self.renderer.is_none() => return self.fail(event_loop, anyhow!(e)),
            Err(e) => {
                // Keep the image that works; go back to its settings.
                eprintln!("warning: {e}");
                self.status = format!("failed: {e}");
                self.revert_controls();
            }
        }
        if let Err(e) = self.sync_camera() {
            return self.fail(event_loop, e);
        }
        self.last_frame = Instant::now();
        self.redraw();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let viewport_height = self.size.1 as f32;
        // The panel sees the event first; what it takes (a click on it, typing into it) does
        // not reach the camera or the keys.
        let (mut to_panel, mut pointer_on_panel, mut typing) = (false, false, false);
        if let (Some(panel), Some(window)) = (&mut self.panel, &self.window)
            && self.controls.panel
        {
            let r = panel.input.on_window_event(window, &event);
            if r.repaint {
                self.draw_next = true;
                window.request_redraw();
            }
            to_panel = r.consumed;
            pointer_on_panel = panel.ctx.egui_wants_pointer_input();
            typing = panel.ctx.egui_wants_keyboard_input();
        }
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => event_loop.exit(),
            WindowEvent::Resized(size) => {
                // A zero size (minimised on some platforms) pauses rendering in about_to_wait;
                // the swapchain keeps its last size until a real one comes.
                if let (Some(gpu), Some(surface)) = (&self.gpu, &mut self.surface) {
                    surface.resize(gpu, size.width, size.height);
                }
                if (size.width, size.height) != self.size {
                    self.size = (size.width, size.height);
                    self.resized_at = Some(Instant::now());
                }
                self.draw_next = true;
                self.redraw();
            }
            WindowEvent::Occluded(occluded) => {
                self.occluded = occluded;
                if !occluded {
                    self.draw_next = true;
                    self.redraw();
                }
            }
            WindowEvent::Focused(false) => self.controls.release_keys(),
            WindowEvent::ModifiersChanged(m) => self.controls.keys.fast = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } if typing && event.state == ElementState::Pressed => {}
            WindowEvent::KeyboardInput { event, .. } => {
                if let Some(key) = key_of(&event) {
                    let r = self.controls.key(key, event.state == ElementState::Pressed, event.repeat);
                    self.apply(event_loop, r);
                }
            }
            WindowEvent::MouseInput { state: ElementState::Pressed, .. } if to_panel || pointer_on_panel => {}
            WindowEvent::MouseInput { state, button, .. } => {
                let pressed = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.dragging.0 = pressed,
                    MouseButton::Right | MouseButton::Middle => self.dragging.1 = pressed,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let Some(last) = self.cursor
                    && (self.dragging.0 || self.dragging.1)
                {
                    let (dx, dy) = ((p.0 - last.0) as f32, (p.1 - last.1) as f32);
                    let r = self.controls.drag(dx, dy, self.dragging.1, viewport_height);
                    self.apply(event_loop, r);
                }
                self.cursor = Some(p);
            }
            WindowEvent::CursorLeft { .. } => self.cursor = None,
            WindowEvent::MouseWheel { .. } if to_panel || pointer_on_panel => {}
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                let r = self.controls.scroll(steps);
                self.apply(event_loop, r);
            }
            WindowEvent::DroppedFile(path) => {
                let r = self.controls.action(&Action::Open(path.display().to_string()), viewport_height);
                self.apply(event_loop, r);
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.error.is_some() || event_loop.exiting() {
            return;
        }
        let minimised = self.window.as_ref().and_then(|w| w.is_minimized()).unwrap_or(false);
        if minimised || self.occluded || self.size.0 == 0 || self.size.1 == 0 {
            // Nothing to show: sleep until the window manager says otherwise.
            event_loop.set_control_flow(ControlFlow::Wait);
            return;
        }
        // Open a scene asked for, or replace the renderer when the window size or the
        // settings changed (once the size has settled), when no other build is in flight.
        if self.building.is_none()
            && self.gpu.is_some()
            && let Some(name) = self.pending_open.take()
        {
            self.start_build(Some(name));
        }
        let wanted = self.wanted();
        if self.building.is_none() && self.gpu.is_some() && !self.renderer_matches(&wanted) {
            let settle = self.resized_at.map(|t| t + RESIZE_SETTLE);
            match settle {
                Some(at) if Instant::now() < at => {
                    event_loop.set_control_flow(ControlFlow::WaitUntil(at));
                    return;
                }
                _ => {
                    // A new size alone keeps the scene and its photon map: only the
                    // size-dependent passes of the photon map renderer are rebuilt.
                    let size = (wanted.settings.width, wanted.settings.height);
                    match &mut self.renderer {
                        Some((view, built)) if same_but_size(built, &wanted) => match view.resize(size.0, size.1) {
                            Ok(true) => {
                                self.resized_at = None;
                                *built = wanted;
                            }
                            Ok(false) => self.start_build(None),
                            Err(e) => return self.fail(event_loop, e.into()),
                        },
                        _ => self.start_build(None),
                    }
                }
            }
        }
        if let Some(at) = self.retry_at {
            // The swapchain had nothing to give: try again shortly rather than spin.
            event_loop.set_control_flow(ControlFlow::WaitUntil(at));
            if Instant::now() >= at {
                self.redraw();
            }
            return;
        }
        if self.building.is_some() {
            // The finished build wakes the loop; keep the title's and the panel's status fresh.
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(250)));
            self.redraw();
            return;
        }
        event_loop.set_control_flow(ControlFlow::Wait);
        self.redraw();
    }
}
