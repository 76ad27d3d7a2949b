//! Results for people and viewers: VTK XML (`.vtu`) for ParaView and meshio.
//!
//! Entry point: [`vtu::write_vtu`].

pub mod vtu;
