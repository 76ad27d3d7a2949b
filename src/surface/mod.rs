//! Contact surfaces built from the mesh by the Sierra rules.
