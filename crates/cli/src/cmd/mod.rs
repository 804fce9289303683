//! One module per subcommand.

pub mod batch;
pub mod check;
pub mod contacts;
pub mod cspace;
pub mod demo;
pub mod interference;
pub mod intervals;
pub mod part;
pub mod place;
pub mod plan;
pub mod poses;
pub mod render;
pub mod sweep;
