//! Fuzzes the run-state reader (`--resume`, `scx merge`): whatever the bytes of a state file, scx must
//! read them or refuse them with an error, never panic, loop or ask for unbounded memory. Each input is
//! decoded as it is, and again with its header made valid (magic, length, CRC-32 of the payload
//! recomputed), so that mutations reach the CBOR payload and the checks of its meaning instead of
//! stopping at the checksum. A state that decodes, of a small built-in scene it matches, is finished
//! into its report, as `scx merge` would.
#![no_main]

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::run::persist::decode;
use scene_complexity::{finish, SavedRun, StopReason};

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

/// Finishes a decoded state into its report when its scene is a small built-in cube it matches (cheap
/// to rebuild; any other scene would need files the fuzzer does not have).
fn report(saved: SavedRun) {
    let name = &saved.identity.scene.name;
    if !matches!(name.as_str(), "@cube:1" | "@cube:2" | "@cube:3") {
        return;
    }
    let Ok(scene) = scene_complexity::load(name) else {
        return;
    };
    let same = scene.fingerprint() == saved.identity.scene.fingerprint
        && scene.patch_count() as u64 == saved.identity.scene.patches;
    if same {
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
    if let Ok(saved) = decode("fuzz.scx", data) {
        report(saved);
    }
    if let Some(fixed) = with_valid_header(data) {
        if let Ok(saved) = decode("fuzz.scx", &fixed) {
            report(saved);
        }
    }
});
