//! The robot controller (the NIST executor's design): action leaves put
//! canonical robot commands into a bounded queue; a consumer thread
//! executes them in order and reports each completion back, and the
//! waiting leaf succeeds on the tick after. Dropping the sender ends the
//! consumer; [`Controller::shutdown`] joins it and returns what it ran.

use rustc_hash::FxHashSet;
use serde::Serialize;
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::thread::JoinHandle;
use std::time::Duration;

/// A canonical robot command: the leaf's ID and its port values.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Command {
    /// 1-based, in the order the commands were issued.
    pub seq: u64,
    pub node: u32,
    pub command: String,
    pub args: Vec<(String, String)>,
    /// The 1-based plan step.
    pub step: Option<usize>,
}

pub struct Controller {
    tx: Option<SyncSender<Command>>,
    done_rx: Receiver<u64>,
    done: FxHashSet<u64>,
    /// Commands whose completion nobody waits for any more.
    forgotten: FxHashSet<u64>,
    next: u64,
    /// Completions received so far.
    received: u64,
    worker: Option<JoinHandle<Vec<Command>>>,
}

impl Controller {
    /// Starts the consumer. `capacity` bounds the queue (a full queue makes
    /// the ticking thread wait: back-pressure); each command takes `work`.
    pub fn start(capacity: usize, work: Duration) -> Controller {
        let (tx, rx) = mpsc::sync_channel::<Command>(capacity.max(1));
        let (done_tx, done_rx) = mpsc::channel::<u64>();
        let worker = std::thread::Builder::new()
            .name("btc-controller".into())
            .spawn(move || {
                let mut log = Vec::new();
                for cmd in rx {
                    if !work.is_zero() {
                        std::thread::sleep(work);
                    }
                    let seq = cmd.seq;
                    log.push(cmd);
                    // The engine may be gone already; completions are then moot.
                    let _ = done_tx.send(seq);
                }
                log
            })
            .ok();
        Controller {
            tx: Some(tx),
            done_rx,
            done: FxHashSet::default(),
            forgotten: FxHashSet::default(),
            next: 0,
            received: 0,
            worker,
        }
    }

    /// Queues a command (waiting while the queue is full); returns its seq.
    pub fn submit(&mut self, mut cmd: Command) -> u64 {
        self.next += 1;
        cmd.seq = self.next;
        let seq = self.next;
        let sent = self.tx.as_ref().is_some_and(|tx| tx.send(cmd).is_ok());
        if !sent {
            // No consumer: complete it here so no leaf waits forever.
            self.received += 1;
            self.done.insert(seq);
        }
        seq
    }

    /// Collects the completions reported so far.
    pub fn poll(&mut self) {
        while let Ok(seq) = self.done_rx.try_recv() {
            self.received += 1;
            self.complete(seq);
        }
    }

    fn complete(&mut self, seq: u64) {
        if !self.forgotten.remove(&seq) {
            self.done.insert(seq);
        }
    }

    /// Nobody waits for command `seq` any more (its leaf was halted): it
    /// still executes, and its completion is dropped.
    pub fn forget(&mut self, seq: u64) {
        if !self.done.remove(&seq) {
            self.forgotten.insert(seq);
        }
    }

    /// Whether command `seq` has completed (consumes the completion).
    pub fn take_done(&mut self, seq: u64) -> bool {
        self.done.remove(&seq)
    }

    /// Waits until command `seq` completes.
    pub fn wait(&mut self, seq: u64) {
        while !self.done.contains(&seq) {
            match self.done_rx.recv() {
                Ok(s) => {
                    self.received += 1;
                    self.complete(s);
                }
                Err(_) => return,
            }
        }
    }

    /// Blocks until some completion is at hand (or `timeout` passes), when
    /// commands are outstanding: the engine then ticks on events, not in a
    /// busy loop.
    pub fn wait_any(&mut self, timeout: Duration) {
        self.poll();
        if !self.done.is_empty() || self.received == self.next {
            return;
        }
        if let Ok(s) = self.done_rx.recv_timeout(timeout) {
            self.received += 1;
            self.complete(s);
        }
    }

    pub fn issued(&self) -> u64 {
        self.next
    }

    /// Closes the queue, lets the consumer finish what is queued and
    /// returns every command it executed, in order.
    pub fn shutdown(mut self) -> Vec<Command> {
        self.tx = None;
        self.worker
            .take()
            .and_then(|w| w.join().ok())
            .unwrap_or_default()
    }
}

impl Drop for Controller {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}
