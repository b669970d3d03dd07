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

use std::sync::Arc;
use std::task::{Context, Poll};
use tokio::sync::Notify;
use tower_lsp::jsonrpc::{Request, Response};
use tower_lsp::{LspService, Server};
use tower_service::Service;

/// Serves LSP on stdin/stdout until the client sends `exit` (or closes
/// stdin).
pub async fn serve_stdio() {
    let (service, socket) = LspService::new(server::Backend::new);
    let exited = Arc::new(Notify::new());
    let service = ExitWatch {
        inner: service,
        exited: exited.clone(),
    };
    // tower-lsp's `serve` returns only when stdin ends; editors keep it
    // open after `exit`, so stop on `exit` too.
    tokio::select! {
        () = Server::new(tokio::io::stdin(), tokio::io::stdout(), socket).serve(service) => {}
        () = exited.notified() => {}
    }
}

/// Passes requests through and tells when `exit` has been handled.
struct ExitWatch<S> {
    inner: S,
    exited: Arc<Notify>,
}

impl<S> Service<Request> for ExitWatch<S>
where
    S: Service<Request, Response = Option<Response>>,
    S::Future: Send + 'static,
{
    type Response = Option<Response>;
    type Error = S::Error;
    type Future = std::pin::Pin<
        Box<dyn std::future::Future<Output = Result<Option<Response>, S::Error>> + Send>,
    >;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), S::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, req: Request) -> Self::Future {
        let exit = req.method() == "exit";
        let fut = self.inner.call(req);
        let exited = self.exited.clone();
        Box::pin(async move {
            let r = fut.await;
            if exit {
                exited.notify_one();
            }
            r
        })
    }
}

/// [`serve_stdio`] on a runtime of its own (for the `btc lsp` command).
pub fn run_stdio() -> std::io::Result<()> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    rt.block_on(serve_stdio());
    // Tokio reads stdin on a blocking thread that waits for the next line
    // even after `exit`; do not wait for it.
    rt.shutdown_background();
    Ok(())
}
