//! Navigation runs: the streaming truth → navigation → errors pipeline over scenarios
//! ([`pipeline`]), navigation over recorded increments ([`recorded`]) and the typed run
//! options every front end shares ([`options`]), and the output-epoch rule ([`epochs`]).

pub mod epochs;
pub mod options;
pub mod pipeline;
pub mod recorded;
pub mod run;
pub mod spp;
pub mod truth_rows;
