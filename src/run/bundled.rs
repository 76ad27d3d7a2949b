//! The scenes built into the `seam` binary, so that an installed binary (with no source
//! tree beside it) can write them out (`seam example NAME`) and `seam run` with no
//! problem file can solve the default one.

use std::path::{Path, PathBuf};

/// A bundled scene: its name, what it shows, and its files (name, contents).
pub struct Bundled {
    pub name: &'static str,
    pub about: &'static str,
    pub files: &'static [(&'static str, &'static [u8])],
}

/// The scene `seam run` solves when given no problem file.
pub const DEFAULT: &str = "two_blocks";

/// Every bundled scene.
pub const SCENES: &[Bundled] = &[
    Bundled {
        name: "two_blocks",
        about: "two blocks meshed apart, joined by a gap conductance (steady)",
        files: &[
            (
                "problem.toml",
                include_bytes!("../../examples/two_blocks/problem.toml"),
            ),
            (
                "contact.i",
                include_bytes!("../../examples/two_blocks/contact.i"),
            ),
            (
                "contact_run.i",
                include_bytes!("../../examples/two_blocks/contact_run.i"),
            ),
            (
                "contact.toml",
                include_bytes!("../../examples/two_blocks/contact.toml"),
            ),
            (
                "two_blocks.exo",
                include_bytes!("../../examples/two_blocks/two_blocks.exo"),
            ),
        ],
    },
    Bundled {
        name: "busbar_joint",
        about: "a bolted copper lap joint carrying 1000 A: voltage and temperature with electrical and thermal contact conductances (steady)",
        files: &[
            (
                "problem.toml",
                include_bytes!("../../examples/busbar_joint/problem.toml"),
            ),
            (
                "contact.i",
                include_bytes!("../../examples/busbar_joint/contact.i"),
            ),
            (
                "busbar_joint.exo",
                include_bytes!("../../examples/busbar_joint/busbar_joint.exo"),
            ),
        ],
    },
];

/// The bundled scene `name`.
pub fn find(name: &str) -> Option<&'static Bundled> {
    SCENES.iter().find(|s| s.name == name)
}

/// Write scene `name` into `dir` (made if missing); returns its problem file. A file
/// that exists already is left alone and is an error: nothing is overwritten.
pub fn write(name: &str, dir: &Path) -> Result<PathBuf, String> {
    let scene = find(name).ok_or_else(|| {
        let names: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
        format!(
            "no bundled scene `{name}`\n  help: the scenes are: {}",
            names.join(", ")
        )
    })?;
    if let Some((f, _)) = scene.files.iter().find(|(f, _)| dir.join(f).exists()) {
        return Err(format!(
            "{} exists already\n  help: give another folder, or remove the scene written there before",
            dir.join(f).display()
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for (f, bytes) in scene.files {
        let path = dir.join(f);
        std::fs::write(&path, bytes)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(dir.join("problem.toml"))
}

/// What `seam example` does: with no name the list of scenes (a line each), with one the
/// scene written into `dir` (default: a folder named after it) and how to run it.
pub fn command(name: Option<&str>, dir: Option<PathBuf>) -> Result<String, String> {
    let Some(name) = name else {
        let lines: Vec<String> = SCENES
            .iter()
            .map(|s| format!("{:14} {}", s.name, s.about))
            .collect();
        return Ok(lines.join("\n"));
    };
    let dir = dir.unwrap_or_else(|| PathBuf::from(name));
    let problem = write(name, &dir)?;
    Ok(format!(
        "wrote {}: solve it with `seam run {}`",
        dir.display(),
        problem.display()
    ))
}
