//! The navigator process's subscriptions to the topics of the held aiding readings (one per
//! source of the list in [`crate::aiding::readings`], where the configuration wants it), drained
//! into the hold queue before every IMU sample.

use ipc_types::{Health, names};
use rins_runtime::ipc::{IpcError, IpcNode};
use rins_runtime::stage_io::StageInput;

use crate::aiding::readings::{AidingQueue, HeldPayload, ReadingSink, held_readings};
use crate::config::NavigatorConfig;

/// [`HeldInputs`] from the list of held readings.
macro_rules! held_inputs {
    ($($(#[$doc:meta])* $variant:ident($field:ident: $reading:ident) from $topic:ident: $payload:ident
        => $build:ident, rank $rank:literal, subscribed if $wanted:expr;)+) => {
        /// The topic of every held reading, subscribed when the configuration wants it.
        pub(crate) struct HeldInputs {
            $($(#[$doc])* $field: Option<StageInput<ipc_types::$payload>>,)+
        }

        impl HeldInputs {
            /// Subscribes, on `node`, to the topics a navigator configured by `config` reads.
            pub(crate) fn new(node: &IpcNode, config: &NavigatorConfig) -> Result<Self, IpcError> {
                Ok(Self {
                    $($field: {
                        let wanted: fn(&NavigatorConfig) -> bool = $wanted;
                        match wanted(config) {
                            true => Some(StageInput::new(node, names::$topic)?),
                            false => None,
                        }
                    },)+
                })
            }

            /// Holds in `queue`, for the navigator `nav`, every reading queued on the topics, in
            /// the list's order.
            pub(crate) fn drain(
                &self,
                counters: &mut Health,
                queue: &mut AidingQueue,
                nav: &mut impl ReadingSink,
            ) -> Result<(), IpcError> {
                $(if let Some(input) = &self.$field {
                    input.drain(counters, |p| queue.hold(p.reading(), nav))?;
                })+
                Ok(())
            }
        }
    };
}

held_readings!(held_inputs);
