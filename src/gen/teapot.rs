//! The `teapot` database (not yet written).

use super::NffWriter;

/// The SPD program's default size factor.
pub const DEFAULT_SIZE: u32 = 1;

/// Write the database at size factor `size`.
pub fn generate(_size: u32, _w: &mut NffWriter) {}
