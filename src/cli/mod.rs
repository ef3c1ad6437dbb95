//! The `rendersim` command line behind `main.rs`: its arguments in clap's
//! terms ([`args`]), what each command does ([`commands`]) the spinner of long
//! commands ([`progress`]) and the lines it
//! prints for benchmarks and measurements ([`print`]), device profiles ([`device`]), the commands that
//! measure on a GPU ([`measuring`]). All simulation logic
//! lives in the library.

pub mod args;
pub mod cluster;
pub mod commands;
pub mod device;
pub mod lod;
pub mod measuring;
pub mod print;
pub mod progress;
