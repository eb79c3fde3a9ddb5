//! scx: the information-theoretic scene complexity framework of Feixas, del Acebo, Bekaert and Sbert,
//! *An information theory framework for the analysis of scene complexity* (Eurographics 1999).
//!
//! Data flows one way: [`scene`] -> global lines ([`sample`]) -> hits ([`trace`]) -> pairs and counts
//! ([`sample`]) -> measures ([`measure`]) -> report.

#![forbid(unsafe_op_in_unsafe_fn)]

pub mod crosscheck;
pub mod geom;
pub mod measure;
pub mod refine;
pub mod reproduce;
pub mod run;
pub mod sample;
pub mod scene;
pub mod scenes;
pub mod trace;
