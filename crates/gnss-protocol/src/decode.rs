//! Receiver byte stream → epochs.
