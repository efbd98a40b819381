//! The keyboard: winit's key events as the viewer's [`Key`]s.

use rastergi::passes::film::Show;
use winit::event::KeyEvent;
use winit::keyboard::{Key as LogicalKey, KeyCode, NamedKey, PhysicalKey};

use super::controls::Key;

/// The viewer's meaning of a keyboard event: movement by key position (WASD wherever the
/// layout puts those letters), the rest by position or by the character typed.
pub(super) fn key_of(event: &KeyEvent) -> Option<Key> {
    if let PhysicalKey::Code(code) = event.physical_key {
        let key = match code {
            KeyCode::KeyW | KeyCode::ArrowUp => Some(Key::Forward),
            KeyCode::KeyS | KeyCode::ArrowDown => Some(Key::Back),
            KeyCode::KeyA | KeyCode::ArrowLeft => Some(Key::Left),
            KeyCode::KeyD | KeyCode::ArrowRight => Some(Key::Right),
            KeyCode::KeyE | KeyCode::PageUp => Some(Key::Up),
            KeyCode::KeyQ | KeyCode::PageDown => Some(Key::Down),
            KeyCode::ShiftLeft | KeyCode::ShiftRight => Some(Key::Fast),
            KeyCode::Tab => Some(Key::ToggleMode),
            KeyCode::Home => Some(Key::Home),
            KeyCode::Digit1 | KeyCode::Numpad1 => Some(Key::Show(Show::Full)),
            KeyCode::Digit2 | KeyCode::Numpad2 => Some(Key::Show(Show::Direct)),
            KeyCode::Digit3 | KeyCode::Numpad3 => Some(Key::Show(Show::Indirect)),
            KeyCode::Digit4 | KeyCode::Numpad4 => Some(Key::Show(Show::PhotonMap)),
            KeyCode::NumpadAdd => Some(Key::ExposureUp),
            KeyCode::NumpadSubtract => Some(Key::ExposureDown),
            KeyCode::BracketLeft => Some(Key::FewerPhotons),
            KeyCode::BracketRight => Some(Key::MorePhotons),
            KeyCode::Comma => Some(Key::CoarserGrid),
            KeyCode::Period => Some(Key::FinerGrid),
            KeyCode::KeyP => Some(Key::Screenshot),
            KeyCode::KeyN => Some(Key::ToggleDenoise),
            KeyCode::KeyJ => Some(Key::SunWest),
            KeyCode::KeyL => Some(Key::SunEast),
            KeyCode::KeyI => Some(Key::SunHigher),
            KeyCode::KeyK => Some(Key::SunLower),
            KeyCode::KeyH | KeyCode::F1 => Some(Key::TogglePanel),
            KeyCode::Escape => Some(Key::Quit),
            _ => None,
        };
        if key.is_some() {
            return key;
        }
    }
    match &event.logical_key {
        LogicalKey::Character(c) if c == "+" || c == "=" => Some(Key::ExposureUp),
        LogicalKey::Character(c) if c == "-" || c == "_" => Some(Key::ExposureDown),
        LogicalKey::Named(NamedKey::Escape) => Some(Key::Quit),
        _ => None,
    }
}
