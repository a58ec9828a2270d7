//! The browser camera explorer behind `obscura serve`: a local HTTP/WebSocket server (axum on
//! tokio) that renders a scene progressively and streams each pass to a page, which changes the
//! camera's keys, orbits, focuses on a click and compares distributed with post-process blur.
//!
//! - [`View`] is a scene file with a page's changes to its `[camera]` keys, resolution and spp,
//!   validated by re-parsing with the scene layer (so the errors name the same keys), and
//!   rendered within the explorer's limits ([`MAX_EDGE`], [`MAX_PIXELS`], [`MAX_SPP`]): a
//!   page asking for more is refused, a scene file asking for more is previewed at them
//!   ([`Clamp`]);
//! - [`Session`] is one page: its scene built once, one worker thread rendering its view pass by
//!   pass, cancelled and restarted on every change; a perspective stereo pair renders both
//!   eyes each pass and is shown composed as `obscura render` composes it (side by side, or
//!   the red-cyan anaglyph; a `separate` pair side by side), its two films counting twice
//!   against the pixel limits;
//! - [`router`] is the API and the embedded page (no outside hosts); [`run`] serves it.
//!
//! See docs/explorer.md for the API.
#![deny(missing_docs)]

mod error;
mod request;
mod server;
mod session;
mod stereo;
mod view;

pub use error::ExploreError;
pub use server::{Explorer, MAX_SESSIONS, camera_types, router};
pub use session::{Frame, Session, Status, coordinates, depth_at, png_bytes};
pub use view::{Clamp, MAX_EDGE, MAX_PIXELS, MAX_SPP, View, ViewChange};

use std::io::Write;
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

/// What `obscura serve` was asked for.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// The address to listen on (127.0.0.1 unless the user says otherwise).
    pub host: IpAddr,
    /// The port; 0 picks a free one.
    pub port: u16,
    /// Render threads per page; None for one per core.
    pub threads: Option<usize>,
}

/// Loads the scene, listens, prints `obscura serve: http://HOST:PORT/` on standard output and
/// serves until the process is stopped.
pub fn run(options: ServeOptions) -> Result<(), ExploreError> {
    let view = View::load(&options.scene)?;
    for clamp in view.clamps() {
        eprintln!("obscura serve: note: {}", clamp.message);
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| ExploreError::Internal(format!("cannot start the server runtime: {e}")))?;
    runtime.block_on(async move {
        let addr = SocketAddr::new(options.host, options.port);
        let listener = tokio::net::TcpListener::bind(addr)
            .await
            .map_err(|e| ExploreError::Internal(format!("cannot listen on {addr}: {e}")))?;
        let local = listener
            .local_addr()
            .map_err(|e| ExploreError::Internal(e.to_string()))?;
        let mut out = std::io::stdout();
        let _ = writeln!(out, "obscura serve: http://{local}/");
        let _ = out.flush();
        let app = router(Explorer::new(view, options.threads));
        axum::serve(listener, app)
            .await
            .map_err(|e| ExploreError::Internal(format!("server: {e}")))
    })
}
