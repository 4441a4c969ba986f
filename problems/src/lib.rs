//! # czid-problems: inverse problems built from laws, forward models and optimizers
