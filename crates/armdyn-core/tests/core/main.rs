//! The integration tests of armdyn-core, one crate: a test file of its own would be a
//! crate of its own, instantiating the generic algorithms again (tens of seconds of
//! compile each at one codegen unit), so each file is a module here.

mod common;

mod alloc;
mod assert_close;
mod batch;
mod centroidal;
mod derivatives;
mod floating;
mod identities;
mod integrate;
mod manifold;
mod minverse;
mod regressor;
mod sin_cos;
mod transposition;
