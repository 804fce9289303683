//! Prints the placement regression scenarios ([A] Figs. 15-17) as JSON: `cargo run -p stackplan-planner --example
//! regress_place --release`.

#[allow(clippy::print_stdout)]
fn main() {
    let value = stackplan_planner::regress::regress_place();
    println!("{}", serde_json::to_string_pretty(&value).unwrap_or_default());
}
