//! Every chapter of the czid book is included here so that `cargo test` compiles and runs its code blocks.
