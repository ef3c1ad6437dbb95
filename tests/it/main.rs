//! rendersim's integration tests, in one binary (fewer binaries to link on
//! a 2-core machine, as ripgrep and NeXosim do). Each module is one topic;
//! `common` holds the helpers several share. Run one topic with
//! `cargo test --test it <module>::`.

mod architecture;
mod binning;
mod bottleneck;
mod cannot_finish;
mod cli;
mod common;
mod conservation;
mod determinism;
mod devices;
mod display_oracles;
mod estimation;
mod extreme;
mod forsyth;
mod fuzz;
mod golden;
mod lavapipe_policy;
mod lod_select;
mod measure;
mod meshopt_crosscheck;
mod model_sweep;
mod multi_rate;
mod nvidia_policy;
mod obj_files;
mod outputs;
mod pacing;
mod pipeline_oracles;
mod pixelflow;
mod present;
mod readback;
mod replay;
mod replay_round_trip;
mod shards;
mod sortbuf;
mod state_sorting;
mod table1_split;
mod tearing;
mod timeline;
mod unified;
mod view_cells;
mod vr;
mod vrr;
mod walkthrough;
mod walkthrough_lod;
mod walkthrough_scenes;
