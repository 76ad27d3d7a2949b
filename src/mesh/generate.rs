//! Mesh generators for tests, examples and benchmarks.
