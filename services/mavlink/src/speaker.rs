//! How rins frames what it sends: who it speaks as, the sequence number every frame shares, and
//! the signature when a key is set.

use std::io;
use std::sync::atomic::{AtomicU8, Ordering};

use mavlink::{MavHeader, SigningData};

use crate::dialect::MavMessage;

/// Largest MAVLink 2 frame (header 10, payload 255, checksum 2, signature 13).
pub(crate) const MAX_FRAME: usize = 280;

/// Who rins speaks as, the sequence number every frame it sends shares, and its signer.
pub(crate) struct Speaker {
    system: u8,
    component: u8,
    sequence: AtomicU8,
    signer: Option<SigningData>,
}

impl Speaker {
    /// `msg` framed as MAVLink 2 into `buf`, signed when a key is set; the frame's length.
    pub(crate) fn frame(&self, msg: &MavMessage, buf: &mut [u8; MAX_FRAME]) -> Option<usize> {
        let header = MavHeader {
            system_id: u32::from(self.system),
            component_id: self.component,
            sequence: self.sequence.fetch_add(1, Ordering::Relaxed),
        };
        let mut cursor = io::Cursor::new(&mut buf[..]);
        mavlink::write_v2_msg_signed(&mut cursor, header, msg, self.signer.as_ref()).ok()?;
        Some(cursor.position() as usize)
    }
}

impl Speaker {
    /// Speaks as `(system, component)`, signing with `signer` when there is one.
    pub(crate) fn new(system: u8, component: u8, signer: Option<SigningData>) -> Self {
        Self {
            system,
            component,
            sequence: AtomicU8::new(0),
            signer,
        }
    }

    /// The system id rins speaks as.
    pub(crate) fn system(&self) -> u8 {
        self.system
    }
}
