//! Planted-effect cases (placeholder, filled below).
