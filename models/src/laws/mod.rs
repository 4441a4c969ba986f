//! Cohesive laws.
