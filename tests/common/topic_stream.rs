//! A topic of a running pipeline followed in the background: `rins echo TOPIC` as a child, its JSON
//! lines collected as they come, so that a test can wait for a condition while it drives the input.

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde_json::Value;

use super::Isolated;

pub struct TopicStream {
    child: Child,
    samples: Arc<Mutex<Vec<Value>>>,
    reader: Option<JoinHandle<()>>,
}

impl TopicStream {
    /// Follows `topic` (as `rins echo` names it) from now on, in the wire form (`--raw`): the
    /// tests compare codes and bits with the payload constants.
    pub fn start(ipc: &Isolated, topic: &str) -> Self {
        let mut child = ipc
            .command()
            .args(["echo", topic, "--raw", "--timeout", "0"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start rins echo");
        let stdout = child.stdout.take().expect("echo stdout");
        let samples = Arc::new(Mutex::new(Vec::new()));
        let reader = {
            let samples = Arc::clone(&samples);
            std::thread::spawn(move || {
                for line in BufReader::new(stdout).lines() {
                    let Ok(line) = line else { break };
                    if let Ok(v) = serde_json::from_str::<Value>(&line) {
                        samples.lock().unwrap_or_else(|e| e.into_inner()).push(v);
                    }
                }
            })
        };
        Self {
            child,
            samples,
            reader: Some(reader),
        }
    }

    /// Samples received so far.
    pub fn len(&self) -> usize {
        self.samples.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    /// A copy of the samples from index `from` on.
    pub fn since(&self, from: usize) -> Vec<Value> {
        let all = self.samples.lock().unwrap_or_else(|e| e.into_inner());
        all.get(from..).map(<[Value]>::to_vec).unwrap_or_default()
    }

    /// The last sample, if any.
    pub fn last(&self) -> Option<Value> {
        let all = self.samples.lock().unwrap_or_else(|e| e.into_inner());
        all.last().cloned()
    }

    /// Waits up to `limit` for a sample from index `from` on that satisfies `done`; returns its
    /// index and the sample, or panics naming `what` and the last sample seen.
    pub fn wait_for(
        &self,
        what: &str,
        from: usize,
        limit: Duration,
        done: impl Fn(&Value) -> bool,
    ) -> (usize, Value) {
        let deadline = Instant::now() + limit;
        let mut checked = from;
        loop {
            {
                let all = self.samples.lock().unwrap_or_else(|e| e.into_inner());
                if let Some(i) = (checked..all.len()).find(|&i| done(&all[i])) {
                    return (i, all[i].clone());
                }
                checked = checked.max(all.len());
            }
            if Instant::now() >= deadline {
                panic!(
                    "no sample {what} within {limit:?} ({checked} samples); last: {}",
                    self.last().map_or("none".into(), |v| v.to_string())
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for TopicStream {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
    }
}
