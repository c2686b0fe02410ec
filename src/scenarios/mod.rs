//! Ready-made reproductions of published tests, shared by the examples and the integration
//! tests: the quasi-static load test and the drop-weight impact tests of the reference arch
//! (Pulatsu, Gonen & Lourenço 2021).

pub mod arch_impact;
pub mod arch_static;
