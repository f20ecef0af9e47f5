//! The paper's results that need more than one command: computed by library functions here, which
//! the report commands call.

mod section9;

pub use section9::{Section9Inputs, section9};
