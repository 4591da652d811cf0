//! 8-lane batches.
