//! Reports of an analysis as data: the JSON document of `scx analyze --format json`, the per-patch and
//! per-object tables (`--patches`, `--objects`) and the sparse form-factor matrix (`--form-factors`).
//!
//! The command line writes these as files; the Python binding hands them over as dictionaries, numpy
//! arrays and scipy matrices. Both take them from here, so that a number has one source and the same
//! name wherever it is read.

mod document;
mod form_factors;
mod rows;
mod tables;

pub use document::{
    bundle, json, reliability_json, skipped_reason, Context, Process, SCHEMA_VERSION,
};
pub use form_factors::{form_factor, FormFactors};
pub use rows::{finite, positive_zero, rows, Row};
pub use tables::{object_table, patch_table, Column, Table, Values};
