//! The receiving ports this process created, by iceoryx2 port id, so that a short-lived tool can
//! remove the connection segments that lead to them once they are gone.
//!
//! A connection between a publisher and a subscriber lives in a /dev/shm segment named after both
//! ports' ids. When the subscriber goes, the segment stays until its publisher next looks at its
//! subscribers, which a publisher that rarely sends (the simulator's fault confirmations) may not
//! do for a long time. The segment is of no use to anyone then; unlinking its name does not
//! disturb the publisher, which keeps its mapping and later finds the name already gone.

use std::sync::Mutex;

static RECEIVERS: Mutex<Vec<u128>> = Mutex::new(Vec::new());

/// Records a subscriber's port id.
pub(crate) fn record_receiver(port_id: u128) {
    RECEIVERS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(port_id);
}

/// The port ids of every subscriber this process created.
pub fn receivers() -> Vec<u128> {
    RECEIVERS.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// Whether the /dev/shm entry `name` is a connection segment (of any publisher) to the receiving
/// port `port_id`: iceoryx2 names them `PREFIX…_SENDER_RECEIVER.connection`.
pub fn is_connection_to(name: &str, port_id: u128) -> bool {
    name.strip_suffix(".connection")
        .and_then(|stem| stem.rsplit_once('_'))
        .is_some_and(|(_, receiver)| receiver == port_id.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_connection_is_recognised_by_its_receiver_id() {
        let name =
            "p_b9fc73e5_237684681809310667331902419200_79228359046092940776185049354.connection";
        assert!(is_connection_to(name, 79228359046092940776185049354));
        assert!(!is_connection_to(name, 237684681809310667331902419200));
        assert!(!is_connection_to(name, 9354));
        assert!(!is_connection_to(
            "p_b9fc73e5_1_79228359046092940776185049354.data",
            79228359046092940776185049354
        ));
    }
}
