//! A recorder fed from other threads without ever holding them up.
//!
//! The threads that take samples off shared memory must not wait on the disk: a slow write there
//! would make them miss samples of every topic, not only of the recording. So they hand each
//! sample to a bounded queue and go on; when the queue is full the sample is dropped and counted,
//! and the summary says how many. A sample travels by value in a fixed inline buffer (the queue's
//! slots are allocated once, when it is made), so sending allocates nothing.
//!
//! A writer thread that stops on an error (a full disk) says so to the senders at once
//! ([`RecordSender::writer_failed`]), so that the recording is not carried on in vain and its end
//! can report what was not recorded.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender, TrySendError};

use crate::cdr::Recordable;
use crate::error::RecordError;
use crate::schema::MAX_PAYLOAD;
use crate::writer::{ChannelId, RecordSummary, Recorder};

/// One sample on its way to the writer thread.
#[derive(Clone, Copy)]
struct Sample {
    channel: ChannelId,
    log_time_ns: u64,
    publish_time_ns: u64,
    len: u16,
    bytes: [u8; MAX_PAYLOAD],
}

// `Sample::len` holds any payload length.
const _: () = assert!(MAX_PAYLOAD <= u16::MAX as usize);

/// Why [`RecordSender::try_send`] did not queue a sample; every case is counted as a drop of its
/// topic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dropped {
    /// The queue is full: the writer is behind.
    Full,
    /// The writer thread has ended (it failed; its join handle has the error).
    WriterGone,
    /// The payload's length is not the channel's payload size (a sample of another type), or is
    /// larger than any payload ([`MAX_PAYLOAD`]).
    WrongLength,
    /// The channel was not registered with the recorder.
    UnknownChannel,
}

/// The sending side: cheap to clone, one per thread that takes samples in. The writer thread
/// finishes the file once every clone is dropped.
#[derive(Clone)]
pub struct RecordSender {
    tx: Sender<Sample>,
    slots: Arc<[Slot]>,
    state: Arc<WriterState>,
}

/// What the writer thread tells the senders while it runs.
#[derive(Default)]
struct WriterState {
    /// Samples written so far.
    written: AtomicU64,
    /// Set when the writer stopped on an error: nothing sent from then on is written.
    failed: AtomicBool,
}

/// What the senders know of one channel: its payload size, and its drops.
struct Slot {
    size: usize,
    dropped: AtomicU64,
}

impl std::fmt::Debug for RecordSender {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordSender")
            .field("dropped", &self.dropped_total())
            .finish_non_exhaustive()
    }
}

impl RecordSender {
    /// Queues one sample of `channel` (the payload's bytes) for writing, without blocking; when it
    /// cannot, the sample is dropped, counted, and the reason returned.
    pub fn try_send(
        &self,
        channel: ChannelId,
        log_time_ns: u64,
        publish_time_ns: u64,
        payload: &[u8],
    ) -> Result<(), Dropped> {
        let Some(slot) = self.slots.get(usize::from(channel.0)) else {
            return Err(Dropped::UnknownChannel);
        };
        // Checked here rather than by the writer, which would stop the whole recording on it.
        // (A layout built outside this crate could be larger than any payload; it does not fit.)
        let result = if payload.len() != slot.size || payload.len() > MAX_PAYLOAD {
            Err(Dropped::WrongLength)
        } else {
            let mut sample = Sample {
                channel,
                log_time_ns,
                publish_time_ns,
                // Fits: a payload size, at most MAX_PAYLOAD, which fits a u16 (checked at compile
                // time).
                len: payload.len() as u16,
                bytes: [0; MAX_PAYLOAD],
            };
            sample.bytes[..payload.len()].copy_from_slice(payload);
            self.tx.try_send(sample).map_err(|e| match e {
                TrySendError::Full(_) => Dropped::Full,
                TrySendError::Disconnected(_) => Dropped::WriterGone,
            })
        };
        if result.is_err() {
            slot.dropped.fetch_add(1, Ordering::Relaxed);
        }
        result
    }

    /// [`RecordSender::try_send`] of a typed payload.
    pub fn try_send_payload<T: Recordable>(
        &self,
        channel: ChannelId,
        log_time_ns: u64,
        publish_time_ns: u64,
        payload: &T,
    ) -> Result<(), Dropped> {
        self.try_send(channel, log_time_ns, publish_time_ns, payload.as_bytes())
    }

    /// Samples dropped so far, all topics.
    pub fn dropped_total(&self) -> u64 {
        self.slots
            .iter()
            .map(|s| s.dropped.load(Ordering::Relaxed))
            .sum()
    }

    /// Samples the writer thread has written so far, all topics.
    pub fn written_total(&self) -> u64 {
        self.state.written.load(Ordering::Relaxed)
    }

    /// Whether the writer thread stopped on an error (its join handle has it): what is sent from
    /// then on is dropped, and the file is incomplete.
    pub fn writer_failed(&self) -> bool {
        self.state.failed.load(Ordering::Acquire)
    }
}

/// The writing side of [`record_channel`]: [`RecordReceiver::run`] writes what arrives until
/// every sender is gone.
pub struct RecordReceiver {
    rx: Receiver<Sample>,
    slots: Arc<[Slot]>,
    state: Arc<WriterState>,
    recorder: Recorder,
}

impl std::fmt::Debug for RecordReceiver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordReceiver")
            .field("recorder", &self.recorder)
            .finish_non_exhaustive()
    }
}

impl RecordReceiver {
    /// Writes every sample that arrives until all senders are dropped, then finishes the file.
    /// Stops at the first write error (the senders then count their samples as dropped) and
    /// flags it to them ([`RecordSender::writer_failed`]).
    pub fn run(self) -> Result<RecordSummary, RecordError> {
        let state = Arc::clone(&self.state);
        let result = self.write_all();
        if result.is_err() {
            state.failed.store(true, Ordering::Release);
        }
        result
    }

    fn write_all(mut self) -> Result<RecordSummary, RecordError> {
        for sample in self.rx.iter() {
            self.recorder.write(
                sample.channel,
                sample.log_time_ns,
                sample.publish_time_ns,
                &sample.bytes[..usize::from(sample.len)],
            )?;
            self.state
                .written
                .store(self.recorder.samples_written(), Ordering::Relaxed);
        }
        let mut summary = self.recorder.finish()?;
        // Every sender is gone, so the counts are final.
        for (topic, slot) in summary.topics.iter_mut().zip(self.slots.iter()) {
            topic.dropped = slot.dropped.load(Ordering::Relaxed);
        }
        summary.samples_dropped = summary.topics.iter().map(|t| t.dropped).sum();
        Ok(summary)
    }
}

/// A queue of `capacity` samples in front of `recorder`, whose channels must all be registered
/// already. Run the receiver in the thread of your choice; [`spawn_writer`] does it in a new one.
pub fn record_channel(recorder: Recorder, capacity: usize) -> (RecordSender, RecordReceiver) {
    let (tx, rx) = crossbeam_channel::bounded(capacity);
    let slots: Arc<[Slot]> = (0..=u16::MAX)
        .map_while(|i| recorder.channel_info(ChannelId(i)))
        .map(|(_, layout)| Slot {
            size: layout.size,
            dropped: AtomicU64::new(0),
        })
        .collect();
    let state = Arc::new(WriterState::default());
    let sender = RecordSender {
        tx,
        slots: Arc::clone(&slots),
        state: Arc::clone(&state),
    };
    let receiver = RecordReceiver {
        rx,
        slots,
        state,
        recorder,
    };
    (sender, receiver)
}

/// Starts a thread that writes `recorder` from a queue of `capacity` samples (its channels must
/// all be registered already). Dropping every [`RecordSender`] ends the thread, which finishes
/// the file; its join handle gives the summary.
pub fn spawn_writer(
    recorder: Recorder,
    capacity: usize,
) -> std::io::Result<(RecordSender, JoinHandle<Result<RecordSummary, RecordError>>)> {
    let (sender, receiver) = record_channel(recorder, capacity);
    let handle = std::thread::Builder::new()
        .name("rins-recorder".to_string())
        .spawn(move || receiver.run())?;
    Ok((sender, handle))
}

/// Waits for the writer thread of [`spawn_writer`] and returns its summary.
pub fn join_writer(
    handle: JoinHandle<Result<RecordSummary, RecordError>>,
) -> Result<RecordSummary, RecordError> {
    handle.join().map_err(|_| RecordError::WriterPanicked)?
}
