//! Feeds arbitrary bytes to the recording reader as if they were a recording file.
//!
//! Beyond "never panics, never aborts on an allocation": every message handed out carries a
//! payload of its type's size, the details kept never exceed the counts, and reading ends.

#![no_main]

use libfuzzer_sys::fuzz_target;
use rins_recording::{MAX_SKIP_DETAILS, Messages};

fuzz_target!(|data: &[u8]| {
    let Ok(mut messages) = Messages::new(data, "fuzz") else {
        return;
    };
    for message in &mut messages {
        match message {
            Ok(message) => assert_eq!(message.payload.len(), message.layout.size),
            Err(_) => break,
        }
    }
    // Ended: a further call hands out nothing.
    assert!(messages.next().is_none());
    assert!(messages.skipped().len() <= MAX_SKIP_DETAILS);
    assert!(messages.skipped().len() as u64 <= messages.skipped_count());
    assert!(messages.damaged_chunks().len() <= MAX_SKIP_DETAILS);
    assert!(messages.damaged_chunks().len() as u64 <= messages.damaged_chunk_count());
});
