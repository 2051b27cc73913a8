//! The bake crate's tests, one binary: a module per topic.

mod atlas;
mod layers;
