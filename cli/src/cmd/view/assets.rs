//! The page, embedded in the binary: nothing is read from the file system and the page
//! loads nothing from elsewhere.

/// The page.
pub const INDEX_HTML: &str = include_str!("page/index.html");
/// Its script.
pub const VIEW_JS: &str = include_str!("page/view.js");
/// Its style.
pub const VIEW_CSS: &str = include_str!("page/view.css");
