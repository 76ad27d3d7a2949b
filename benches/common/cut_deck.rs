//! The contact deck of the cut bar, shared by `benches/mpi_scaling.rs` and
//! `tests/mpi.rs`: side A the first box's face at x = 1 (`surface_3`), side B the second
//! box's (`surface_4`), joined by `enforcement` (the lines of its enforcement block).

/// The deck's text.
pub fn cut_deck(enforcement: &str) -> String {
    format!(
        "begin contact definition cut\n\
         contact surface a contains surface_3\n\
         contact surface b contains surface_4\n\
         begin interaction\n side a a\n side b b\n end\n\
         begin enforcement\n {enforcement}\n end\n\
         end\n"
    )
}
