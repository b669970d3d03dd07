//! ARIAC 2023 trial files: the YAML layer ([`yaml`]), the typed trial
//! ([`model`]) and the reader that turns one into the other with
//! diagnostics ([`read`]).

pub mod model;
pub mod read;
pub mod yaml;

pub use model::*;
pub use read::read;
