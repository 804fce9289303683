//! One module per subcommand.

pub mod demo;
pub mod intervals;
pub mod part;
