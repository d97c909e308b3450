//! Running a model: the driver (integrate to the end time, sample, stop on request), the
//! recorder of the channels and the sinks that receive each contact of a force evaluation.

pub mod driver;
pub mod recorder;
pub mod sink;
