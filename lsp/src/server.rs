//! The tower-lsp shell: requests in, library calls, responses out. The
//! workspace sits behind a std mutex that is never held across an
//! `.await`: every request computes under the lock, then answers.

use crate::analysis::Analysis;
use crate::convert::LineIndex;
use crate::workspace::{FileDiagnostics, Workspace};
use crate::{completion, edits, highlight, navigation, symbols};
use btc_pddl::diagnostic::{Diagnostic, Severity};
use std::sync::{Arc, Mutex, MutexGuard};
use tower_lsp::jsonrpc::{Error, Result};
use tower_lsp::lsp_types::*;
use tower_lsp::{Client, LanguageServer};

pub struct Backend {
    client: Client,
    ws: Arc<Mutex<Workspace>>,
    /// Bumped by every edit: diagnostics computed for an older text are
    /// not worth publishing (a newer edit supersedes them).
    generation: std::sync::atomic::AtomicU64,
}

impl Backend {
    pub fn new(client: Client) -> Backend {
        Backend {
            client,
            ws: Arc::new(Mutex::new(Workspace::new())),
            generation: std::sync::atomic::AtomicU64::new(0),
        }
    }

    fn ws(&self) -> MutexGuard<'_, Workspace> {
        // A panic while holding the lock poisons it; the workspace is still
        // consistent (salsa inputs are set atomically), so keep serving.
        self.ws.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Re-checks and publishes diagnostics for every affected file, unless
    /// another edit came in meanwhile (it publishes instead).
    async fn publish(&self) {
        use std::sync::atomic::Ordering;
        let mine = self.generation.fetch_add(1, Ordering::SeqCst) + 1;
        // Let edits already read in be applied first.
        tokio::task::yield_now().await;
        if self.generation.load(Ordering::SeqCst) != mine {
            return;
        }
        let batches: Vec<(Url, Vec<tower_lsp::lsp_types::Diagnostic>, Option<i32>)> =
            isolated(|| {
                let mut ws = self.ws();
                let all = ws.diagnostics();
                all.into_iter()
                    .filter_map(|fd| convert_file(&ws, fd))
                    .collect()
            })
            .unwrap_or_default();
        if self.generation.load(Ordering::SeqCst) != mine {
            return;
        }
        for (uri, diags, version) in batches {
            self.client.publish_diagnostics(uri, diags, version).await;
        }
    }

    /// Runs `f` on the analysis of the document `uri`, if it is a rules file.
    /// A panic answers this request with an internal error; the server
    /// keeps serving (the workspace is consistent: inputs are set whole).
    fn with_analysis<T>(
        &self,
        uri: &Url,
        f: impl FnOnce(&Analysis) -> Option<T>,
    ) -> Result<Option<T>> {
        isolated(|| {
            let path = path_of(uri)?;
            let ws = self.ws();
            let a = Analysis::new(&ws, &path)?;
            f(&a)
        })
    }
}

/// Runs a request's work; a panic becomes the request's error response.
fn isolated<T>(f: impl FnOnce() -> T) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|e| {
        let what = e
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| e.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Error {
            code: tower_lsp::jsonrpc::ErrorCode::InternalError,
            message: format!("btc failed on this request: {what}").into(),
            data: None,
        }
    })
}

/// The database path of a document URI (an absolute file path).
pub fn path_of(uri: &Url) -> Option<btc_lang::path::FilePath> {
    let p = uri.to_file_path().ok()?;
    Some(btc_lang::path::FilePath::new(p))
}

fn convert_file(
    ws: &Workspace,
    fd: FileDiagnostics,
) -> Option<(Url, Vec<tower_lsp::lsp_types::Diagnostic>, Option<i32>)> {
    let uri = Url::from_file_path(fd.path.as_path()?).ok()?;
    let text = ws.text(&fd.path).unwrap_or_default();
    let lines = Lines::new(ws, LineIndex::new(text));
    let capped =
        btc_pddl::render::capped(&fd.diagnostics, btc_pddl::limits::MAX_DIAGNOSTICS_PER_FILE);
    let diags = capped.iter().map(|d| to_lsp(&lines, d)).collect();
    Some((uri, diags, fd.version))
}

/// Line indexes for converting one file's diagnostics: the file's own, and
/// one per other file a label points into, each built once. (Building one
/// per label made publishing a huge file's diagnostics take seconds.)
pub struct Lines<'a> {
    ws: &'a Workspace,
    own: LineIndex<'a>,
    others: std::cell::RefCell<
        std::collections::HashMap<btc_pddl::source::FileId, Option<(Url, LineIndex<'a>)>>,
    >,
}

impl<'a> Lines<'a> {
    /// `own` indexes the text the diagnostics' primary spans are in.
    pub fn new(ws: &'a Workspace, own: LineIndex<'a>) -> Lines<'a> {
        Lines {
            ws,
            own,
            others: std::cell::RefCell::new(std::collections::HashMap::new()),
        }
    }

    /// The location of a span in any file of the workspace.
    fn location(&self, span: btc_pddl::source::Span) -> Option<Location> {
        let mut others = self.others.borrow_mut();
        let entry = others.entry(span.file).or_insert_with(|| {
            let path = self.ws.path_of(span.file)?;
            let uri = Url::from_file_path(path.as_path()?).ok()?;
            let text = self.ws.text(&path)?;
            Some((uri, LineIndex::new(text)))
        });
        let (uri, ix) = entry.as_ref()?;
        Some(Location::new(uri.clone(), ix.range(span)))
    }
}

/// A btc diagnostic as LSP sees it: range, code, message with its hint,
/// secondary labels as related information.
pub fn to_lsp(lines: &Lines, d: &Diagnostic) -> tower_lsp::lsp_types::Diagnostic {
    let mut message = d.message.clone();
    if let Some(h) = &d.hint {
        message.push_str("\nhint: ");
        message.push_str(h);
    }
    let related: Vec<DiagnosticRelatedInformation> = d
        .labels
        .iter()
        .filter_map(|l| {
            Some(DiagnosticRelatedInformation {
                location: lines.location(l.span)?,
                message: l.message.clone(),
            })
        })
        .collect();
    tower_lsp::lsp_types::Diagnostic {
        range: lines.own.range(d.span),
        severity: Some(match d.severity {
            Severity::Error => DiagnosticSeverity::ERROR,
            Severity::Warning => DiagnosticSeverity::WARNING,
        }),
        code: Some(NumberOrString::String(d.code.to_owned())),
        source: Some("btc".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        ..tower_lsp::lsp_types::Diagnostic::default()
    }
}

pub fn capabilities() -> ServerCapabilities {
    ServerCapabilities {
        text_document_sync: Some(TextDocumentSyncCapability::Options(
            TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(TextDocumentSyncKind::INCREMENTAL),
                save: Some(TextDocumentSyncSaveOptions::Supported(true)),
                ..TextDocumentSyncOptions::default()
            },
        )),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        document_symbol_provider: Some(OneOf::Left(true)),
        workspace_symbol_provider: Some(OneOf::Left(true)),
        completion_provider: Some(CompletionOptions {
            trigger_characters: Some(vec!["?".into(), "(".into(), ":".into(), "[".into()]),
            ..CompletionOptions::default()
        }),
        signature_help_provider: Some(SignatureHelpOptions {
            trigger_characters: Some(vec!["(".into(), ",".into()]),
            retrigger_characters: None,
            work_done_progress_options: WorkDoneProgressOptions::default(),
        }),
        semantic_tokens_provider: Some(SemanticTokensServerCapabilities::SemanticTokensOptions(
            SemanticTokensOptions {
                legend: highlight::legend(),
                full: Some(SemanticTokensFullOptions::Bool(true)),
                range: None,
                work_done_progress_options: WorkDoneProgressOptions::default(),
            },
        )),
        document_formatting_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: WorkDoneProgressOptions::default(),
        })),
        document_highlight_provider: Some(OneOf::Left(true)),
        inlay_hint_provider: Some(OneOf::Left(true)),
        code_action_provider: Some(CodeActionProviderCapability::Options(CodeActionOptions {
            code_action_kinds: Some(vec![CodeActionKind::QUICKFIX]),
            ..CodeActionOptions::default()
        })),
        ..ServerCapabilities::default()
    }
}

#[tower_lsp::async_trait]
impl LanguageServer for Backend {
    async fn initialize(&self, _: InitializeParams) -> Result<InitializeResult> {
        Ok(InitializeResult {
            capabilities: capabilities(),
            server_info: Some(ServerInfo {
                name: "btc".into(),
                version: Some(env!("CARGO_PKG_VERSION").into()),
            }),
        })
    }

    async fn initialized(&self, _: InitializedParams) {
        // Watch PDDL and rules files on disk, so that a domain edited
        // outside the editor re-checks the rules that use it. Clients that
        // cannot register dynamically answer with an error: nothing lost.
        let watchers = ["**/*.pddl", "**/*.btrules"]
            .iter()
            .map(|g| FileSystemWatcher {
                glob_pattern: GlobPattern::String((*g).into()),
                kind: None,
            })
            .collect();
        let reg = Registration {
            id: "btc-watch".into(),
            method: "workspace/didChangeWatchedFiles".into(),
            register_options: serde_json::to_value(DidChangeWatchedFilesRegistrationOptions {
                watchers,
            })
            .ok(),
        };
        let _ = self.client.register_capability(vec![reg]).await;
    }

    async fn shutdown(&self) -> Result<()> {
        Ok(())
    }

    async fn did_open(&self, p: DidOpenTextDocumentParams) {
        // Notifications have no response to carry an error: a panic is
        // dropped, and the server keeps serving.
        let _ = isolated(|| {
            if let Some(path) = path_of(&p.text_document.uri) {
                self.ws()
                    .open(&path, p.text_document.text, p.text_document.version);
            }
        });
        self.publish().await;
    }

    async fn did_change(&self, p: DidChangeTextDocumentParams) {
        let _ = isolated(|| {
            if let Some(path) = path_of(&p.text_document.uri) {
                self.ws()
                    .change(&path, p.content_changes, p.text_document.version);
            }
        });
        self.publish().await;
    }

    async fn did_save(&self, _: DidSaveTextDocumentParams) {}

    async fn did_close(&self, p: DidCloseTextDocumentParams) {
        let _ = isolated(|| {
            if let Some(path) = path_of(&p.text_document.uri) {
                self.ws().close(&path);
            }
        });
        self.publish().await;
    }

    async fn did_change_watched_files(&self, p: DidChangeWatchedFilesParams) {
        let _ = isolated(|| {
            let mut ws = self.ws();
            for c in p.changes {
                if let Some(path) = path_of(&c.uri) {
                    ws.changed_on_disk(&path);
                }
            }
        });
        self.publish().await;
    }

    async fn hover(&self, p: HoverParams) -> Result<Option<Hover>> {
        let pp = p.text_document_position_params;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            navigation::hover(a, off)
        })
    }

    async fn goto_definition(
        &self,
        p: GotoDefinitionParams,
    ) -> Result<Option<GotoDefinitionResponse>> {
        let pp = p.text_document_position_params;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            let mut found: Vec<Location> = navigation::definition(a, off)
                .iter()
                .filter_map(|p| a.location(p))
                .collect();
            match found.len() {
                0 => None,
                1 => found.pop().map(GotoDefinitionResponse::Scalar),
                _ => Some(GotoDefinitionResponse::Array(found)),
            }
        })
    }

    async fn references(&self, p: ReferenceParams) -> Result<Option<Vec<Location>>> {
        let pp = p.text_document_position;
        let include = p.context.include_declaration;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            let def = navigation::definition(a, off);
            let places = navigation::references(a, off)?;
            Some(
                places
                    .iter()
                    .filter(|pl| include || !def.contains(pl))
                    .filter_map(|pl| a.location(pl))
                    .collect(),
            )
        })
    }

    async fn document_symbol(
        &self,
        p: DocumentSymbolParams,
    ) -> Result<Option<DocumentSymbolResponse>> {
        self.with_analysis(&p.text_document.uri, |a| {
            Some(DocumentSymbolResponse::Nested(symbols::document_symbols(a)))
        })
    }

    async fn symbol(&self, p: WorkspaceSymbolParams) -> Result<Option<Vec<SymbolInformation>>> {
        isolated(|| Some(symbols::workspace_symbols(&self.ws(), &p.query)))
    }

    async fn completion(&self, p: CompletionParams) -> Result<Option<CompletionResponse>> {
        let pp = p.text_document_position;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            Some(CompletionResponse::Array(completion::completion(a, off)))
        })
    }

    async fn signature_help(&self, p: SignatureHelpParams) -> Result<Option<SignatureHelp>> {
        let pp = p.text_document_position_params;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            completion::signature_help(a, off)
        })
    }

    async fn semantic_tokens_full(
        &self,
        p: SemanticTokensParams,
    ) -> Result<Option<SemanticTokensResult>> {
        self.with_analysis(&p.text_document.uri, |a| {
            Some(SemanticTokensResult::Tokens(SemanticTokens {
                result_id: None,
                data: highlight::semantic_tokens(a),
            }))
        })
    }

    async fn formatting(&self, p: DocumentFormattingParams) -> Result<Option<Vec<TextEdit>>> {
        self.with_analysis(&p.text_document.uri, edits::format)
    }

    async fn rename(&self, p: RenameParams) -> Result<Option<WorkspaceEdit>> {
        let pp = p.text_document_position;
        let r = self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            Some(navigation::rename(a, off, &p.new_name))
        });
        match r? {
            None => Ok(None),
            Some(Ok(edit)) => Ok(Some(edit)),
            Some(Err(e)) => Err(Error::invalid_params(e.0)),
        }
    }

    async fn prepare_rename(
        &self,
        p: TextDocumentPositionParams,
    ) -> Result<Option<PrepareRenameResponse>> {
        let r = self.with_analysis(&p.text_document.uri, |a| {
            let off = a.line_index().offset(p.position);
            Some(navigation::prepare_rename(a, off).map(|s| a.range(s)))
        });
        match r? {
            None => Ok(None),
            Some(Ok(range)) => Ok(Some(PrepareRenameResponse::Range(range))),
            Some(Err(e)) => Err(Error::invalid_params(e.0)),
        }
    }

    async fn document_highlight(
        &self,
        p: DocumentHighlightParams,
    ) -> Result<Option<Vec<DocumentHighlight>>> {
        let pp = p.text_document_position_params;
        self.with_analysis(&pp.text_document.uri, |a| {
            let off = a.line_index().offset(pp.position);
            navigation::highlights(a, off)
        })
    }

    async fn inlay_hint(&self, p: InlayHintParams) -> Result<Option<Vec<InlayHint>>> {
        self.with_analysis(&p.text_document.uri, |a| {
            Some(highlight::inlay_hints(a, p.range))
        })
    }

    async fn code_action(&self, p: CodeActionParams) -> Result<Option<CodeActionResponse>> {
        let uri = p.text_document.uri.clone();
        if let Some(path) = path_of(&uri).filter(|p| p.has_extension("pddl")) {
            return isolated(|| {
                let ws = self.ws();
                let text = ws.text(&path)?;
                let lines = Lines::new(&ws, LineIndex::new(text));
                let conv = |d: &Diagnostic| to_lsp(&lines, d);
                Some(
                    edits::pddl_code_actions(&ws, &path, &uri, p.range, &conv)
                        .into_iter()
                        .map(CodeActionOrCommand::CodeAction)
                        .collect(),
                )
            });
        }
        self.with_analysis(&p.text_document.uri, |a| {
            let lines = Lines::new(a.ws, LineIndex::new(a.text));
            let conv = |d: &Diagnostic| to_lsp(&lines, d);
            Some(
                edits::code_actions(a, &uri, p.range, &conv)
                    .into_iter()
                    .map(CodeActionOrCommand::CodeAction)
                    .collect(),
            )
        })
    }
}
