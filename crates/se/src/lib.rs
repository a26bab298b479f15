//! The vworks simulation engine (SE).
//!
//! Not built yet: this crate will hold the paper's simulation management module, the event
//! queue, the wait list and the when list, the cycle-boundary synchronisation and the parry
//! collision checks (issue 5). Until then it only re-exports the link step it will call
//! when a workcell is loaded, so embedders have one entry point.

pub use vworks_wslc::link;
