//! Wake-ups between the processes through iceoryx2 event services: the CNC notifies
//! "tick done" after publishing a tick, the PLC notifies "cycle done" after its cycle. They
//! carry no data (the data is in the segment); they only let a sleeping side wake up.

use core::time::Duration;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;

/// Failure of the event plumbing (creating services or ports, notifying, waiting).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("event service {service}: {reason}")]
pub struct EventError {
    /// The iceoryx2 service name.
    pub service: String,
    /// iceoryx2's error.
    pub reason: String,
}

/// Which way a link points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Notifies "tick done", listens for "cycle done".
    Cnc,
    /// Notifies "cycle done", listens for "tick done".
    Plc,
}

/// Service name of an instance's wake-up.
pub fn service_name(instance: &str, event: &str) -> String {
    format!("cncplc/{instance}/{event}")
}

/// One side's notifier and listener.
pub struct EventLink {
    _node: Node<ipc::Service>,
    notifier: Notifier<ipc::Service>,
    listener: Listener<ipc::Service>,
}

impl core::fmt::Debug for EventLink {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("EventLink")
    }
}

fn err(service: &str, e: impl core::fmt::Debug) -> EventError {
    EventError {
        service: service.to_string(),
        reason: format!("{e:?}"),
    }
}

impl EventLink {
    /// Opens (or creates) both event services of `instance` for `side`.
    pub fn open(instance: &str, side: Side) -> Result<Self, EventError> {
        let (notify, listen) = match side {
            Side::Cnc => ("tick_done", "cycle_done"),
            Side::Plc => ("cycle_done", "tick_done"),
        };
        let notify_name = service_name(instance, notify);
        let listen_name = service_name(instance, listen);
        let node = NodeBuilder::new()
            .create::<ipc::Service>()
            .map_err(|e| err(&notify_name, e))?;
        let open = |name: &str| {
            let service_name: ServiceName = name.try_into().map_err(|e| err(name, e))?;
            node.service_builder(&service_name)
                .event()
                .open_or_create()
                .map_err(|e| err(name, e))
        };
        let notifier = open(&notify_name)?
            .notifier_builder()
            .create()
            .map_err(|e| err(&notify_name, e))?;
        let listener = open(&listen_name)?
            .listener_builder()
            .create()
            .map_err(|e| err(&listen_name, e))?;
        Ok(Self {
            _node: node,
            notifier,
            listener,
        })
    }

    /// Wakes the other side.
    pub fn notify(&self) -> Result<(), EventError> {
        self.notifier
            .notify()
            .map(|_| ())
            .map_err(|e| err("notify", e))
    }

    /// Waits up to `timeout` for the other side's notification; `true` when one arrived.
    /// Collapses several pending notifications into one wake-up. A wait that a signal
    /// interrupts (the SIGCONT after the process was stopped, a handler's signal) is a
    /// wake-up without news, not a failure: the caller looks at the heartbeat and its
    /// signals as after any wake-up.
    pub fn wait(&self, timeout: Duration) -> Result<bool, EventError> {
        use iceoryx2::port::listener::ListenerWaitError;
        let mut woken = false;
        match self.listener.timed_wait(|_| woken = true, timeout) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => Ok(woken),
            Err(e) => Err(err("wait", e)),
        }
    }

    /// Consumes pending notifications without blocking; `true` when there were some.
    pub fn poll(&self) -> Result<bool, EventError> {
        let mut woken = false;
        self.listener
            .try_wait(|_| woken = true)
            .map_err(|e| err("poll", e))?;
        Ok(woken)
    }
}
