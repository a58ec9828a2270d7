//! The HTTP and WebSocket API (docs/explorer.md lists it) and the embedded page.

use crate::error::ExploreError;
use crate::request::{Params, pixel};
use crate::session::{Session, coordinates, on_image, png_bytes, preview_depth};
use crate::stereo::{
    Pick, eye_name, eye_of_name, image_width, layout_name, pair_layout, pick, shown,
};
use crate::view::{MAX_EDGE, MAX_PIXELS, MAX_SPP, View, ViewChange};
use axum::Router;
use axum::body::Bytes;
use axum::extract::ws::rejection::WebSocketUpgradeRejection;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path as UrlPath, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use obscura_camera::{Camera, StereoEye};
use obscura_render::{
    CameraKind, DepthOfField, Image, ImageInfo, RenderOptions, RenderScene, SceneDescription,
    StereoLayout, camera_of, compose_stereo, depth_of_field, motion_blur, render, screen_buffers,
    write_image,
};
use serde_json::{Value as Json, json};
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// The most pages (sessions) served at once; each has its own scene and render thread.
pub const MAX_SESSIONS: usize = 16;

/// Samples per pixel of the pinhole image that the post-process comparison blurs.
const POSTPROCESS_SPP: u32 = 16;

/// The camera models the page offers, as the scene format names them: every model the scene
/// layer knows, so a new model appears without a change here.
pub fn camera_types() -> Vec<&'static str> {
    CameraKind::ALL.iter().map(|k| k.name()).collect()
}

/// The server's state: the scene file's view and the pages' sessions.
pub struct Explorer {
    base: View,
    sessions: Mutex<HashMap<u64, Arc<Session>>>,
    next_id: AtomicU64,
    /// Sessions whose scenes are being built, counted against the limit (changed under the
    /// sessions' lock, so that concurrent requests cannot pass it together).
    starting: AtomicUsize,
    threads: Option<usize>,
}

impl Explorer {
    /// An explorer of the scene `base`, rendering with `threads` workers per page (None: one
    /// per core).
    pub fn new(base: View, threads: Option<usize>) -> Arc<Explorer> {
        Arc::new(Explorer {
            base,
            sessions: Mutex::new(HashMap::new()),
            next_id: AtomicU64::new(1),
            starting: AtomicUsize::new(0),
            threads,
        })
    }

    fn sessions(&self) -> std::sync::MutexGuard<'_, HashMap<u64, Arc<Session>>> {
        self.sessions.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Starts a session (builds its scene off the async runtime).
    async fn open(self: &Arc<Self>) -> Result<(u64, Arc<Session>), ExploreError> {
        {
            let sessions = self.sessions();
            if sessions.len() + self.starting.load(Ordering::SeqCst) >= MAX_SESSIONS {
                return Err(ExploreError::Refused {
                    key: "session".into(),
                    message: format!("{MAX_SESSIONS} pages are open already; close one"),
                });
            }
            self.starting.fetch_add(1, Ordering::SeqCst);
        }
        // Released however this ends, also when the request is dropped mid-build.
        let _slot = Slot(&self.starting);
        let (base, threads) = (self.base.clone(), self.threads);
        let started = tokio::task::spawn_blocking(move || Session::start(base, threads))
            .await
            .map_err(|e| ExploreError::Internal(e.to_string()))
            .and_then(|r| r);
        let mut sessions = self.sessions();
        let session = Arc::new(started?);
        let id = self.next_id.fetch_add(1, Ordering::SeqCst);
        sessions.insert(id, session.clone());
        Ok((id, session))
    }

    fn session(&self, id: Option<u64>) -> Result<Option<Arc<Session>>, ExploreError> {
        match id {
            None => Ok(None),
            Some(id) => self
                .sessions()
                .get(&id)
                .cloned()
                .map(Some)
                .ok_or(ExploreError::NoSession(id)),
        }
    }

    /// The session a request must name (`?session=ID`).
    fn named_session(&self, q: &Params) -> Result<Arc<Session>, ExploreError> {
        let id = q.required_session()?;
        self.session(Some(id))?.ok_or(ExploreError::NoSession(id))
    }

    fn view_of(&self, id: Option<u64>) -> Result<View, ExploreError> {
        Ok(match self.session(id)? {
            Some(s) => s.view(),
            None => self.base.clone(),
        })
    }

    /// Sessions open now.
    pub fn session_count(&self) -> usize {
        self.sessions().len()
    }
}

/// A reserved place among the sessions being started; given back when dropped.
struct Slot<'a>(&'a AtomicUsize);

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The router of the page, its assets and the API.
pub fn router(explorer: Arc<Explorer>) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/assets/{file}", get(asset))
        .route("/api/scene", get(scene_json))
        .route("/api/session", post(open_session).delete(close_session))
        .route("/api/view", post(change_view))
        .route("/api/status", get(status))
        .route("/api/focus", post(focus))
        .route("/api/coords", get(coords))
        .route("/api/scene.toml", get(scene_toml))
        .route("/api/image.png", get(image_png))
        .route("/api/image.exr", get(image_exr))
        .route("/api/postprocess.png", get(postprocess))
        .route("/api/ws", get(websocket))
        .with_state(explorer)
}

type Api = State<Arc<Explorer>>;

async fn index() -> Response {
    (
        [(header::CONTENT_TYPE, "text/html; charset=utf-8")],
        include_str!("../assets/index.html"),
    )
        .into_response()
}

async fn asset(UrlPath(file): UrlPath<String>) -> Response {
    let (body, kind) = match file.as_str() {
        "app.js" => (
            include_str!("../assets/app.js"),
            "text/javascript; charset=utf-8",
        ),
        "style.css" => (
            include_str!("../assets/style.css"),
            "text/css; charset=utf-8",
        ),
        _ => return (StatusCode::NOT_FOUND, "no such asset").into_response(),
    };
    ([(header::CONTENT_TYPE, kind)], body).into_response()
}

/// The view's parameters as the page shows them: `resolution` and `spp` as rendered (per eye
/// of a stereo pair), `clamped` the scene file's settings previewed at the explorer's limits,
/// and `stereo` how a pair is shown (null for a single view).
fn view_json(view: &View) -> Json {
    let d = view.description();
    // The image is the crop window's pixels (the whole film without one).
    let [w, h] = d.film.resolution;
    let [x0, x1, y0, y1] = obscura_camera::FilmGeometry::new(d.film.resolution, None, d.film.crop)
        .map_or([0, w, 0, h], |f| f.pixel_bounds());
    let (w, h) = (x1 - x0, y1 - y0);
    let stereo = pair_layout(d).map(|layout| {
        let shown = shown(layout);
        let width = image_width(Some(shown), w);
        json!({
            "layout": layout_name(layout),
            "shown": layout_name(shown),
            "image": [width, h],
        })
    });
    json!({
        "camera": view.camera_json(),
        "resolution": d.film.resolution,
        "spp": d.sampler.spp,
        "clamped": view.clamps(),
        "stereo": stereo,
        "effective": {
            "type": d.camera.kind.name(),
            "lens_radius": d.camera.lens.radius,
            "focal_distance": d.camera.lens.focal_distance,
            "fov": d.camera.fov,
            "shutter": [d.camera.shutter.open, d.camera.shutter.close],
        },
    })
}

async fn scene_json(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let view = x.view_of(q.session()?)?;
    let mut body = view_json(&view);
    body["types"] = json!(camera_types());
    body["limits"] = json!({ "max_edge": MAX_EDGE, "max_pixels": MAX_PIXELS, "max_spp": MAX_SPP });
    body["file"] = json!(view.description().file.display().to_string());
    Ok(axum::Json(body).into_response())
}

async fn open_session(State(x): Api) -> Result<Response, ExploreError> {
    let (id, session) = x.open().await?;
    let mut body = view_json(&session.view());
    body["session"] = json!(id);
    Ok((StatusCode::CREATED, axum::Json(body)).into_response())
}

async fn close_session(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let id = q.required_session()?;
    x.sessions()
        .remove(&id)
        .map(|_| StatusCode::NO_CONTENT.into_response())
        .ok_or(ExploreError::NoSession(id))
}

/// Applies a change to a session's view (restarting its render), or, without a session,
/// only validates it against the scene file's view.
async fn change_view(State(x): Api, q: Params, body: Bytes) -> Result<Response, ExploreError> {
    let change = ViewChange::from_json(&body)?;
    let mut out = match x.session(q.session()?)? {
        Some(s) => {
            let (generation, view) = s.change(&change)?;
            let mut v = view_json(&view);
            v["generation"] = json!(generation);
            v
        }
        None => view_json(&x.base.apply(&change)?),
    };
    out["ok"] = json!(true);
    Ok(axum::Json(out).into_response())
}

async fn status(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let s = x.named_session(&q)?;
    Ok(axum::Json(s.status()).into_response())
}

/// Runs blocking work (ray casts, scene builds, renders) off the async runtime.
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, ExploreError> + Send + 'static,
) -> Result<T, ExploreError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ExploreError::Internal(e.to_string()))?
}

/// Autofocus: the depth under the pixel becomes the session's focal distance.
async fn focus(State(x): Api, q: Params, body: Bytes) -> Result<Response, ExploreError> {
    let (px, py) = pixel(&body)?;
    match x.session(q.session()?)? {
        Some(s) => {
            let depth = {
                let s = s.clone();
                blocking(move || s.depth_at(px, py)).await?
            };
            let mut change = ViewChange::default();
            change.camera.insert("focal_distance".into(), json!(depth));
            let (generation, view) = s.change(&change)?;
            let mut out = view_json(&view);
            out["depth"] = json!(depth);
            out["generation"] = json!(generation);
            Ok(axum::Json(out).into_response())
        }
        None => {
            let base = x.base.clone();
            let depth = blocking(move || {
                preview_depth(RenderScene::build(base.description().clone())?, px, py)
            })
            .await?;
            Ok(axum::Json(json!({ "depth": depth })).into_response())
        }
    }
}

/// The coordinates under a position of the page's image: for a stereo pair's side-by-side
/// image, on the film of the eye whose half it is in (`eye`: "left" or "right"); for an
/// anaglyph, the rig centre's (`eye`: "centre"), which sees a point midway between its red
/// and cyan images.
async fn coords(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let (px, py) = (q.finite("x")?, q.finite("y")?);
    let view = x.view_of(q.session()?)?;
    let d = view.description();
    let centre = camera_of(d)?;
    // The page's image starts at the crop window's first pixel, the film's raster at the
    // full film's.
    let [x0, x1, y0, y1] = Camera::film(&centre).pixel_bounds();
    let (dx, dy) = (x0 as f32, y0 as f32);
    on_image(pair_layout(d).map(shown), x1 - x0, y1 - y0, px, py)?;
    let Some(layout) = pair_layout(d) else {
        let mut c = coordinates(&centre, px + dx, py + dy);
        c["eye"] = Json::Null;
        return Ok(axum::Json(c).into_response());
    };
    let Pick { eye, x: ex, y: ey } = pick(Some(shown(layout)), x1 - x0, px, py);
    let (ex, ey) = (ex + dx, ey + dy);
    let (camera, name) = match (eye, d.stereo_eyes()) {
        (Some(eye), Some([left, right])) => {
            let eye_d = if eye == StereoEye::Left { left } else { right };
            (camera_of(&eye_d)?, eye_name(eye))
        }
        _ => (centre, "centre"),
    };
    let mut c = coordinates(&camera, ex, ey);
    c["eye"] = json!(name);
    Ok(axum::Json(c).into_response())
}

async fn scene_toml(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let view = x.view_of(q.session()?)?;
    Ok((
        [
            (header::CONTENT_TYPE, "application/toml; charset=utf-8"),
            (
                header::CONTENT_DISPOSITION,
                "attachment; filename=\"view.toml\"",
            ),
        ],
        view.to_toml(),
    )
        .into_response())
}

/// The latest frame to save, its passes and its file name's stem: what `obscura render`
/// writes of the view. A stereo pair laid out side by side or as an anaglyph is one image,
/// composed; a `separate` pair is two files (`view-left`, `view-right`), so the request names
/// the eye (`eye=left|right`, which any pair may name).
fn latest(x: &Explorer, q: &Params) -> Result<(Image, u32, String), ExploreError> {
    let s = x.named_session(q)?;
    let eye = q
        .optional("eye")
        .map(|name| {
            eye_of_name(name).ok_or_else(|| ExploreError::Malformed {
                key: "eye".into(),
                message: format!("must be \"left\" or \"right\", got {name:?}"),
            })
        })
        .transpose()?;
    let none_yet = || ExploreError::NothingThere("no frame rendered yet".into());
    let (image, _, passes) = s.latest_image().ok_or_else(none_yet)?;
    match (s.latest_eyes(), eye) {
        (None, None) => Ok((image, passes, "view".into())),
        (None, Some(_)) => Err(ExploreError::Refused {
            key: "eye".into(),
            message: "the view is not a stereo pair ([camera.stereo] on a perspective camera)"
                .into(),
        }),
        (Some(([left, right], _, _, passes)), Some(eye)) => {
            let image = if eye == StereoEye::Left { left } else { right };
            Ok((image, passes, format!("view-{}", eye_name(eye))))
        }
        (Some((_, StereoLayout::Separate, _, _)), None) => Err(ExploreError::Refused {
            key: "eye".into(),
            message: "camera.stereo.layout = \"separate\" saves each eye to its own file, as \
                      `obscura render` writes NAME-left and NAME-right: ask for eye=left or \
                      eye=right"
                .into(),
        }),
        (Some(_), None) => Ok((image, passes, "view".into())),
    }
}

/// `attachment; filename="NAME"`.
fn attachment(name: &str) -> String {
    format!("attachment; filename=\"{name}\"")
}

/// The latest frame as `obscura render` writes it to a file of extension `ext` (`png` or
/// `exr`): the same encoder, so a download is the command line's file byte for byte (the
/// PNG keeps the film's coverage as alpha, which the page's opaque preview frames drop).
async fn image_file(x: &Explorer, q: &Params, ext: &'static str) -> Result<Response, ExploreError> {
    let (image, passes, stem) = latest(x, q)?;
    let bytes = blocking(move || {
        // The writer writes files; a private temporary one, read back and removed.
        let path = std::env::temp_dir().join(format!(
            "obscura-explore-{}-{}.{ext}",
            std::process::id(),
            TEMP_COUNTER.fetch_add(1, Ordering::SeqCst)
        ));
        let info = ImageInfo {
            partial: false,
            samples_per_pixel: passes,
        };
        let written = write_image(&path, &image, &info).and_then(|()| {
            std::fs::read(&path).map_err(|source| obscura_render::RenderError::Io {
                file: path.clone(),
                action: "cannot read back",
                source,
            })
        });
        let _ = std::fs::remove_file(&path);
        Ok(written?)
    })
    .await?;
    let kind = if ext == "png" {
        "image/png"
    } else {
        "image/x-exr"
    };
    Ok((
        [
            (header::CONTENT_TYPE, kind.to_string()),
            (
                header::CONTENT_DISPOSITION,
                attachment(&format!("{stem}.{ext}")),
            ),
        ],
        bytes,
    )
        .into_response())
}

async fn image_png(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    image_file(&x, &q, "png").await
}

async fn image_exr(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    image_file(&x, &q, "exr").await
}

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Potmesil and Chakravarty's post-process blur of a pinhole image of the view, for
/// comparison with the distributed render: for a stereo pair, of each eye, composed as the
/// page shows the pair.
async fn postprocess(State(x): Api, q: Params) -> Result<Response, ExploreError> {
    let dof = match q.text("effect")? {
        "dof" => true,
        "motion" => false,
        other => {
            return Err(ExploreError::Malformed {
                key: "effect".into(),
                message: format!("must be \"dof\" or \"motion\", got {other:?}"),
            });
        }
    };
    let view = x.view_of(q.session()?)?;
    let threads = x.threads;
    let png = blocking(move || {
        let d = view.description();
        let open = d.camera.shutter.open;
        let mut change = ViewChange {
            spp: Some(d.sampler.spp.min(POSTPROCESS_SPP)),
            ..Default::default()
        };
        change.camera.insert("shutter".into(), json!([open, open]));
        if dof {
            change.camera.insert("lens_radius".into(), json!(0.0));
        }
        let sharp = view.apply(&change)?;
        let blur = |real: SceneDescription, sharp: SceneDescription| {
            postprocessed(real, sharp, dof, threads)
        };
        let image = match (
            pair_layout(d),
            d.stereo_eyes(),
            sharp.description().stereo_eyes(),
        ) {
            (Some(layout), Some([real_left, real_right]), Some([sharp_left, sharp_right])) => {
                let (left, right) = (blur(real_left, sharp_left)?, blur(real_right, sharp_right)?);
                compose_stereo(&left, &right, shown(layout)).ok_or_else(|| {
                    ExploreError::Internal("no single image of the pair's layout".into())
                })?
            }
            _ => blur(d.clone(), sharp.description().clone())?,
        };
        png_bytes(&image)
    })
    .await?;
    Ok(([(header::CONTENT_TYPE, "image/png")], png).into_response())
}

/// The post-process blur of `sharp` (a pinhole, instantaneous render of the view `real`) by
/// `real`'s depth (`dof`) or raster velocity buffers.
fn postprocessed(
    real: SceneDescription,
    sharp: SceneDescription,
    dof: bool,
    threads: Option<usize>,
) -> Result<Image, ExploreError> {
    let real = RenderScene::build(real)?;
    let buffers = screen_buffers(&real);
    let sharp = RenderScene::build(sharp)?;
    let outcome = render(
        &sharp,
        RenderOptions {
            threads,
            ..Default::default()
        },
    )
    .map_err(|e| ExploreError::Internal(e.to_string()))?;
    let image = outcome.film.resolve();
    Ok(if dof {
        depth_of_field(
            &image,
            &buffers.depth,
            &DepthOfField::for_camera(&real.camera)?,
        )?
    } else {
        motion_blur(&image, &buffers.velocity)?
    })
}

async fn websocket(
    State(x): Api,
    q: Params,
    upgrade: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Result<Response, ExploreError> {
    // Checked before a session is opened for the socket, so that a refused upgrade leaves
    // none behind.
    let upgrade = upgrade.map_err(|e| ExploreError::BadRequest(e.body_text()))?;
    // A named session is joined (and left open); otherwise the page gets its own, closed
    // with the socket.
    let named = q.session()?;
    let joined = x.session(named)?;
    let (id, session, owned) = match joined {
        Some(s) => (named.unwrap_or_default(), s, false),
        None => {
            let (id, s) = x.open().await?;
            (id, s, true)
        }
    };
    Ok(upgrade.on_upgrade(move |socket| async move {
        talk(socket, id, session).await;
        if owned {
            x.sessions().remove(&id);
        }
    }))
}

/// The socket's conversation: a hello, then frames out and changes in until either side
/// closes.
async fn talk(mut socket: WebSocket, id: u64, session: Arc<Session>) {
    // A new receiver counts the frame already sent as seen; marked unseen, it goes out after
    // the hello. Otherwise a view whose last pass was done before the socket opened (a small
    // scene, a slow browser) never reached the page.
    let mut frames = session.frames();
    frames.mark_changed();
    let mut hello = view_json(&session.view());
    hello["type"] = json!("hello");
    hello["session"] = json!(id);
    if socket
        .send(Message::Text(hello.to_string().into()))
        .await
        .is_err()
    {
        return;
    }
    loop {
        tokio::select! {
            changed = frames.changed() => {
                if changed.is_err() {
                    return;
                }
                let frame = frames.borrow_and_update().clone();
                if let Some(f) = frame {
                    let mut bytes = Vec::with_capacity(12 + f.png.len());
                    bytes.extend_from_slice(&(f.generation as u32).to_le_bytes());
                    bytes.extend_from_slice(&f.pass.to_le_bytes());
                    bytes.extend_from_slice(&f.passes.to_le_bytes());
                    bytes.extend_from_slice(&f.png);
                    if socket.send(Message::Binary(bytes.into())).await.is_err() {
                        return;
                    }
                }
            }
            incoming = socket.recv() => {
                let text = match incoming {
                    Some(Ok(Message::Text(t))) => t,
                    Some(Ok(Message::Close(_))) | None | Some(Err(_)) => return,
                    Some(Ok(_)) => continue,
                };
                let reply = match ViewChange::from_json(text.as_bytes())
                    .and_then(|c| session.change(&c))
                {
                    Ok((generation, view)) => {
                        let mut v = view_json(&view);
                        v["type"] = json!("view");
                        v["generation"] = json!(generation);
                        v
                    }
                    Err(e) => {
                        let mut v = e.body();
                        v["type"] = json!("error");
                        v
                    }
                };
                if socket.send(Message::Text(reply.to_string().into())).await.is_err() {
                    return;
                }
            }
        }
    }
}
