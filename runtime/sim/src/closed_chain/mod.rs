//! The second source's closed-chain simulations (four-bar, planar Gough–Stewart, cooperating
//! arms) as a [`Trace`], with CSV and plots.

mod simulate;

pub use simulate::{scenario_names, simulate, simulate_mechanism, Panel, SimOptions, Trace};
