//! The TADSL language server: the protocol over `tad-ide` and the salsa database, served
//! by `tadslc lsp` on standard input and output.
//!
//! ```text
//! client ──JSON-RPC──▶ server (requests, notifications) ──▶ workspace (documents, Database)
//!                         │ snapshot (a clone of the database)            ▲ edits, in order
//!                         ▼                                                │
//!                      tad-ide (byte offsets) ──convert──▶ protocol values (UTF-16 or UTF-8)
//!                      check worker ──▶ publishDiagnostics + tadsl/scenarioClass
//! ```
//!
//! | module | job |
//! |---|---|
//! | [`transport`] | framing: every client message checked before tower-lsp-server reads it |
//! | [`server`] | the `LanguageServer` methods, concurrency, cancellation, the check worker |
//! | [`workspace`] | open documents over the disk, the database, the written stdlib |
//! | [`convert`] | diagnostics and `tad-ide` answers as protocol values |
//! | [`line_index`] | positions in the negotiated encoding ↔ byte offsets |
//! | [`config`] | settings from the client into checker options |

pub mod config;
pub mod convert;
pub mod line_index;
pub mod server;
pub mod transport;
pub mod workspace;

use tokio::io::{AsyncRead, AsyncWrite};
use tower_lsp_server::{LspService, Server};

/// Serve one client over `input`/`output` until it exits. Messages pass through
/// [`transport`], which answers what is not JSON-RPC itself.
pub async fn serve<I, O>(input: I, output: O)
where
    I: AsyncRead + Unpin + Send + 'static,
    O: AsyncWrite + Unpin + Send + 'static,
{
    let (server_in, filtered) = tokio::io::duplex(1 << 20);
    let (server_out, replies) = tokio::io::duplex(1 << 20);
    let (answers, answered) = tokio::sync::mpsc::unbounded_channel();
    let reading = tokio::spawn(transport::filter_input(input, filtered, answers));
    let writing = tokio::spawn(transport::merge_output(replies, output, answered));
    let (service, socket) = LspService::build(server::Server::new).finish();
    let serving = Server::new(server_in, server_out, socket).serve(service);
    // a client that goes away without `exit` (its end of the pipe closed) must not leave
    // the server running: once the input has ended, it gets a moment to finish
    let gone = async {
        let _ = reading.await;
        tokio::time::sleep(std::time::Duration::from_secs(2)).await;
    };
    tokio::select! {
        _ = serving => {}
        _ = gone => {}
    }
    let _ = tokio::time::timeout(std::time::Duration::from_secs(1), writing).await;
}

/// Serve on standard input and output: `tadslc lsp`.
pub fn run_stdio() -> std::io::Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(serve(tokio::io::stdin(), tokio::io::stdout()));
    // the check worker may still hold a snapshot: do not wait for blocking tasks
    runtime.shutdown_timeout(std::time::Duration::from_millis(100));
    Ok(())
}
