//! The btc language server: `.btrules` diagnostics, navigation into the
//! PDDL domain, completion, quick fixes. A thin layer over the same salsa
//! database as `btc check`; nothing here checks anything itself.
//!
//! [`workspace`] holds the database and the open documents, [`syntax`] and
//! [`analysis`] work out what a position means, the feature modules answer
//! requests, [`server`] speaks LSP (tower-lsp) and [`convert`] is the only
//! place that counts UTF-16.

pub mod analysis;
pub mod completion;
pub mod convert;
pub mod edits;
pub mod highlight;
pub mod navigation;
pub mod server;
pub mod symbols;
pub mod syntax;
pub mod workspace;

pub mod transport;

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use tokio::io::AsyncWriteExt;
use tower_lsp::{LspService, Server};
use transport::{Checked, Framer, Next};

/// What the writer thread does next.
enum Out {
    /// Bytes as tower-lsp framed them (whole messages: its codec writes
    /// each frame from one buffer).
    Raw(Vec<u8>),
    /// End the process once everything before is written.
    Exit(i32),
}

/// tower-lsp's output: every write goes to the writer thread whole.
struct ToWriter(std::sync::mpsc::Sender<Out>);

impl tokio::io::AsyncWrite for ToWriter {
    fn poll_write(
        self: std::pin::Pin<&mut Self>,
        _: &mut std::task::Context<'_>,
        buf: &[u8],
    ) -> std::task::Poll<std::io::Result<usize>> {
        let _ = self.0.send(Out::Raw(buf.to_vec()));
        std::task::Poll::Ready(Ok(buf.len()))
    }

    fn poll_flush(
        self: std::pin::Pin<&mut Self>,
        _: &mut std::task::Context<'_>,
    ) -> std::task::Poll<std::io::Result<()>> {
        std::task::Poll::Ready(Ok(()))
    }

    fn poll_shutdown(
        self: std::pin::Pin<&mut Self>,
        _: &mut std::task::Context<'_>,
    ) -> std::task::Poll<std::io::Result<()>> {
        std::task::Poll::Ready(Ok(()))
    }
}

/// Serves LSP on stdin/stdout (for the `btc lsp` command) until the client
/// sends `exit` or closes stdin; then the process ends with 0 if
/// `shutdown` came first, 1 otherwise. Never returns normally.
pub fn run_stdio() -> std::io::Result<()> {
    let (out_tx, out_rx) = std::sync::mpsc::channel::<Out>();
    std::thread::Builder::new()
        .name("lsp-writer".into())
        .spawn(move || {
            let mut stdout = std::io::stdout().lock();
            for o in out_rx {
                match o {
                    Out::Raw(bytes) => {
                        let _ = stdout.write_all(&bytes).and_then(|()| stdout.flush());
                    }
                    Out::Exit(code) => {
                        let _ = stdout.flush();
                        std::process::exit(code);
                    }
                }
            }
        })?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_stack_size(8 << 20)
        .enable_all()
        .build()?;
    let (to_server, server_in) = tokio::io::duplex(1 << 20);
    let (in_tx, mut in_rx) = tokio::sync::mpsc::unbounded_channel::<Vec<u8>>();
    let shutdown = Arc::new(AtomicBool::new(false));
    {
        let out = out_tx.clone();
        let shutdown = shutdown.clone();
        std::thread::Builder::new()
            .name("lsp-reader".into())
            .spawn(move || read_stdin(&in_tx, &out, &shutdown))?;
    }
    rt.block_on(async move {
        let mut to_server = to_server;
        tokio::spawn(async move {
            while let Some(frame) = in_rx.recv().await {
                if to_server.write_all(&frame).await.is_err() {
                    break;
                }
            }
        });
        let (service, socket) = LspService::new(server::Backend::new);
        Server::new(server_in, ToWriter(out_tx.clone()), socket)
            .serve(service)
            .await;
        let code = if shutdown.load(Ordering::SeqCst) {
            0
        } else {
            1
        };
        let _ = out_tx.send(Out::Exit(code));
        std::future::pending::<()>().await
    });
    Ok(())
}

/// The reader thread: frames, checks, forwards; answers what is not a
/// message; ends the process on `exit` and at the end of stdin.
fn read_stdin(
    to_server: &tokio::sync::mpsc::UnboundedSender<Vec<u8>>,
    out: &std::sync::mpsc::Sender<Out>,
    shutdown: &AtomicBool,
) {
    let reply = |v: serde_json::Value| {
        let _ = out.send(Out::Raw(transport::frame(v.to_string().as_bytes())));
    };
    let mut framer = Framer::new(std::io::stdin().lock());
    loop {
        match framer.next_message() {
            Next::Eof => break,
            Next::Bad(why) => reply(transport::error(
                serde_json::Value::Null,
                transport::PARSE_ERROR,
                &why,
            )),
            Next::Body(body) => match transport::check(&body) {
                Checked::Reply(v) => reply(v),
                Checked::Drop => {}
                Checked::Forward {
                    method,
                    body: fixed,
                } => {
                    match method.as_deref() {
                        Some("shutdown") => shutdown.store(true, Ordering::SeqCst),
                        Some("exit") => break,
                        _ => {}
                    }
                    let body = fixed.unwrap_or(body);
                    if to_server.send(transport::frame(&body)).is_err() {
                        break;
                    }
                }
            },
        }
    }
    // `exit`, or the client is gone: whatever is pending (a request of the
    // server's that was never answered) does not keep the process alive.
    let code = if shutdown.load(Ordering::SeqCst) {
        0
    } else {
        1
    };
    let _ = out.send(Out::Exit(code));
}
