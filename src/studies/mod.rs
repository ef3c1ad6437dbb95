//! Studies that run whole models, above the systems they run:
//!
//! - [`isolate`]: each unit's load alone, the others made free (paper 000
//!   §4.5's bottleneck by isolation);
//! - [`table1`]: paper 000 Table 1's four cells, three calibrated and one
//!   predicted, for a geometry share of the first cell (§4.5.1);
//! - [`replay`]: a real frame capture (PresentMon) replayed through the
//!   frame pipeline, predicted against measured;
//! - [`timeline`]: the picture of paper 000 Figure 4, from a run's trace;
//! - [`device_predictions`]: predicted against measured, per device, as a
//!   system an experiment can run.

pub mod device_predictions;
pub mod isolate;
pub mod replay;
pub mod table1;
pub mod timeline;
