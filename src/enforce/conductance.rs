//! Conductance-coefficient models.
