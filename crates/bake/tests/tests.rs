//! The bake crate's tests, one binary: a module per topic.

mod bandwidth_atlas;
mod layer_selection;
