//! Being written.

use rhai::Engine;

/// Registers this module's script functions.
pub fn register(_engine: &mut Engine) {}
