//! A recorded channel checked against this build: its message encoding, its payload type and
//! its payload version, so that no message of it is misread.

use std::sync::Arc;

use crate::error::ReadError;
use crate::schema::{self, StructLayout};
use crate::writer::{MESSAGE_ENCODING, META_PAYLOAD_VERSION, META_TYPE_NAME};

/// What a channel's metadata resolved to.
pub(crate) struct ChannelInfo {
    pub(crate) topic: Arc<str>,
    pub(crate) layout: &'static StructLayout,
}

/// Checks a channel's metadata against this build's payloads.
pub(crate) fn check_channel(channel: &mcap::Channel<'_>) -> Result<ChannelInfo, ReadError> {
    let topic = channel.topic.clone();
    if channel.message_encoding != MESSAGE_ENCODING {
        return Err(ReadError::Encoding {
            topic,
            encoding: channel.message_encoding.clone(),
        });
    }
    let type_name = channel
        .metadata
        .get(META_TYPE_NAME)
        .cloned()
        .unwrap_or_default();
    let Some(layout) = schema::payload_by_type_name(&type_name) else {
        return Err(ReadError::UnknownType { topic, type_name });
    };
    let version = channel.metadata.get(META_PAYLOAD_VERSION);
    if version.and_then(|v| v.parse::<u16>().ok()) != Some(ipc_types::PAYLOAD_VERSION) {
        return Err(ReadError::VersionMismatch {
            topic,
            found: version.cloned().unwrap_or_else(|| "(none)".to_string()),
            expected: ipc_types::PAYLOAD_VERSION,
        });
    }
    Ok(ChannelInfo {
        topic: Arc::from(topic),
        layout,
    })
}
