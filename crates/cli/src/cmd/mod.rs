//! One module per subcommand.

pub mod cspace;
pub mod demo;
pub mod interference;
pub mod intervals;
pub mod part;
