//! Macro variables as the core stores them: a value or null. Each front end owns its variable
//! map (which number means what) and reads and writes through the core's store: the locals of
//! each call level ([`crate::CallLevel::locals`]) and the common variables
//! ([`crate::Core::common`]).

/// A variable's value: `None` is null (a variable never written, or cleared).
pub type Value = Option<f64>;
