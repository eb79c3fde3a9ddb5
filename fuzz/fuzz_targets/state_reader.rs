//! Fuzzes the run-state reader (`--resume`, `scx merge`): whatever the bytes of a state file, scx must
//! read them or refuse them with an error, never panic, loop or ask for unbounded memory. Each input is
//! decoded as it is, and again with its header made valid (magic, length, CRC-32 of the payload
//! recomputed), so that mutations reach the CBOR payload and the checks of its meaning instead of
//! stopping at the checksum. A state that decodes is checked against a small built-in cube and, when
//! the checks pass, finished into its report, as `scx merge` would.
#![no_main]

use libfuzzer_sys::fuzz_target;
use scene_complexity::{decode_state as decode, finish, StateFile, StopReason};

/// The header of a state file: magic, format version (u32 LE), payload length (u64 LE), CRC-32 (u32 LE).
const MAGIC: &[u8; 8] = b"SCXSTATE";
const HEADER: usize = 24;

/// The input with its header made consistent with its payload (the version as the input has it).
fn with_valid_header(data: &[u8]) -> Option<Vec<u8>> {
    if data.len() < HEADER {
        return None;
    }
    let payload = &data[HEADER..];
    let mut fixed = Vec::with_capacity(data.len());
    fixed.extend_from_slice(MAGIC);
    fixed.extend_from_slice(&data[8..12]);
    fixed.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    fixed.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
    fixed.extend_from_slice(payload);
    Some(fixed)
}

/// Checks a decoded state against a small built-in cube (the one it names when it names one, else
/// `@cube:2`), skipping the fingerprint so that the checks of its meaning run on every mutation, and
/// finishes it into its report when they pass, as `scx merge` would.
fn report(file: StateFile) {
    let name = file.identity().scene.name.clone();
    let name = match name.as_str() {
        "@cube:1" | "@cube:2" | "@cube:3" => name,
        _ => "@cube:2".to_string(),
    };
    let Ok(scene) = scene_complexity::load(&name) else {
        return;
    };
    if let Ok(saved) = file.into_run_of_any_scene(&scene) {
        let _ = finish(
            &scene,
            &saved.identity.spec,
            saved.state,
            StopReason::Lines,
            saved.seconds,
        );
    }
}

fuzz_target!(|data: &[u8]| {
    if let Ok(file) = decode("fuzz.scx", data) {
        report(file);
    }
    if let Some(fixed) = with_valid_header(data) {
        if let Ok(file) = decode("fuzz.scx", &fixed) {
            report(file);
        }
    }
});
