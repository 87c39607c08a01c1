//! One-shot commands to a running process (simulator, fusion): publish one sample on a control
//! topic, and fail clearly when nobody listens.

use std::fmt::Debug;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use rins_runtime::ipc::{IpcNode, IpcSettings};

/// How often to look again for a listener while waiting for one.
const POLL: Duration = Duration::from_millis(20);

/// A control command that was handed to at least one subscriber. Keep it alive until the
/// receiver has taken the sample: the sample lives in the sender's shared memory, and a receiver
/// that had not yet connected would never see it once the sender is gone.
pub struct SentCommand<T: Debug + ZeroCopySend + 'static> {
    _publisher: Publisher<ipc::Service, T, ()>,
}

/// Publishes `value` on `topic` once a subscriber exists, waiting up to `wait` for one; `listener`
/// names the process expected to subscribe, for the error message.
pub fn send<T: Debug + ZeroCopySend + Copy + 'static>(
    node: &IpcNode,
    settings: &IpcSettings,
    topic: &'static str,
    listener: &str,
    value: T,
    wait: Duration,
) -> Result<SentCommand<T>> {
    let name = ServiceName::new(topic).map_err(|e| anyhow!("service name {topic:?}: {e:?}"))?;
    let deadline = Instant::now() + wait;
    let nobody = |detail: String| {
        anyhow!(
            "no {listener} is listening on {topic:?} (IPC prefix {:?}, root {:?}){detail}: start the pipeline with `rins up` first, with the same {} and {}",
            settings.prefix,
            settings.root,
            rins_runtime::ipc::PREFIX_ENV,
            rins_runtime::ipc::ROOT_ENV,
        )
    };
    // Opened, not created: a topic nobody set up means nobody listens. The settings are the
    // existing service's, so no attribute is required here.
    let service = loop {
        let last = match node.service_builder(&name).publish_subscribe::<T>().open() {
            Ok(s) if s.dynamic_config().number_of_subscribers() > 0 => break s,
            Ok(_) => String::new(),
            Err(PublishSubscribeOpenError::DoesNotExist) => String::new(),
            Err(e) => format!(" (last attempt: {e:?})"),
        };
        if Instant::now() >= deadline {
            return Err(nobody(last));
        }
        std::thread::sleep(POLL);
    };
    let publisher = service
        .publisher_builder()
        .create()
        .map_err(|e| anyhow!("cannot create a publisher on {topic:?}: {e:?}"))?;
    let sample = publisher
        .loan_uninit()
        .map_err(|e| anyhow!("loan on {topic:?} failed: {e:?}"))?;
    let receivers = sample
        .write_payload(value)
        .send()
        .map_err(|e| anyhow!("send on {topic:?} failed: {e:?}"))?;
    if receivers == 0 {
        return Err(nobody(" (the listener went away)".into()));
    }
    // Wake a listener that sleeps on the topic's event service; one that polls needs no signal.
    if let Ok(event) = node.service_builder(&name).event().open()
        && let Ok(notifier) = event.notifier_builder().create()
    {
        let _ = notifier.notify();
    }
    Ok(SentCommand {
        _publisher: publisher,
    })
}
