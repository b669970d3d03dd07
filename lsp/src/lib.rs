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

use tower_lsp::{LspService, Server};

/// Serves LSP on stdin/stdout until the client exits.
pub async fn serve_stdio() {
    let (service, socket) = LspService::new(server::Backend::new);
    Server::new(tokio::io::stdin(), tokio::io::stdout(), socket)
        .serve(service)
        .await;
}

/// [`serve_stdio`] on a runtime of its own (for the `btc lsp` command).
pub fn run_stdio() -> std::io::Result<()> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    rt.block_on(serve_stdio());
    Ok(())
}
