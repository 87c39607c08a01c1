//! Epochs → receiver messages, for the simulated receiver.
