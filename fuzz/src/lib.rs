//! Shared by the fuzz targets: a scratch folder of this process for the inputs that the
//! readers take as files (meshes, problem files), and the one check every target makes
//! on an error: that it says something.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `$TMPDIR/seam-fuzz-<pid>`, made once per process.
pub fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("seam-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    })
}

/// Write `bytes` to `name` in the scratch folder and return its path.
pub fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let path = scratch().join(name);
    std::fs::write(&path, bytes).expect("write scratch file");
    path
}

/// An error must say what went wrong: an empty message is a bug too.
pub fn assert_says_something(message: &str) {
    assert!(!message.trim().is_empty(), "an error with an empty message");
}
