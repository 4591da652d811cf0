//! The fuzz targets' checks as a library, so that the corpora can be replayed by a plain
//! test on stable.

pub mod checks;
