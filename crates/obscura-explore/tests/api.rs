//! The explorer's HTTP and WebSocket API, driven through the router (no sockets) and, for the
//! WebSocket, through a real loopback listener.

use axum::body::{Body, to_bytes};
use axum::http::{Request, StatusCode};
use futures_util::{SinkExt, StreamExt};
use obscura_explore::{Explorer, Session, View, ViewChange, router};
use serde_json::{Value, Value as Json, json};
use std::path::PathBuf;
use std::sync::Arc;
use tokio_tungstenite::tungstenite::Message;
use tower::ServiceExt;

/// A 48 x 32 view along -z from z = 5: a unit sphere at the origin (its front at z = 1, depth
/// 4 on the axis) before a wall at z = -2 (depth 7 wherever it is seen).
fn scene_text(spp: u32) -> String {
    format!(
        r#"
[film]
resolution = [48, 32]
[sampler]
spp = {spp}
[integrator]
type = "path"
max_depth = 2
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
[[shapes]]
type = "quad"
origin = [-50.0, -50.0, -2.0]
edge_u = [100.0, 0.0, 0.0]
edge_v = [0.0, 100.0, 0.0]
[[lights]]
type = "environment"
radiance = [1.0, 1.0, 1.0]
"#
    )
}

fn view(spp: u32) -> View {
    View::parse(&PathBuf::from("explore-test.toml"), &scene_text(spp)).unwrap()
}

fn explorer(spp: u32) -> Arc<Explorer> {
    Explorer::new(view(spp), Some(1))
}

async fn call(x: &Arc<Explorer>, method: &str, uri: &str, body: &str) -> (StatusCode, Vec<u8>) {
    let request = Request::builder()
        .method(method)
        .uri(uri)
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let response = router(x.clone()).oneshot(request).await.unwrap();
    let status = response.status();
    let bytes = to_bytes(response.into_body(), 1 << 26).await.unwrap();
    (status, bytes.to_vec())
}

/// An answer that must be an error in the documented form: JSON `{"error": MESSAGE, "key":
/// KEY-or-null}` with a message; its status and body.
/// Autofocus at (`px`, `py`) of session `id`'s image: the depth found, and the answer.
async fn focus_at(x: &Arc<Explorer>, id: u64, px: f64, py: f64) -> (f64, Value) {
    let uri = format!("/api/focus?session={id}");
    let (status, v) = call_json(x, "POST", &uri, &json!({"x": px, "y": py}).to_string()).await;
    assert_eq!(status, StatusCode::OK, "({px}, {py}): {v}");
    (v["depth"].as_f64().unwrap(), v)
}

/// Asserts that the request is refused with `status` and a JSON error naming `key`.
async fn assert_refused(
    x: &Arc<Explorer>,
    (method, uri, body): (&str, &str, &str),
    status: StatusCode,
    key: &str,
) {
    let (got, v) = call_error(x, method, uri, body).await;
    assert_eq!(
        (got, &v["key"]),
        (status, &json!(key)),
        "{method} {uri} {body}: {v}"
    );
}

/// The PNG file `obscura render` writes of `image` (the renderer's own writer).
fn cli_png(image: &obscura_render::Image) -> Vec<u8> {
    let path =
        std::env::temp_dir().join(format!("obscura-explore-test-{}.png", std::process::id()));
    let info = obscura_render::ImageInfo {
        partial: false,
        samples_per_pixel: 1,
    };
    obscura_render::write_image(&path, image, &info).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    bytes
}

async fn call_error(x: &Arc<Explorer>, method: &str, uri: &str, body: &str) -> (StatusCode, Value) {
    let request = Request::builder()
        .method(method)
        .uri(uri)
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let response = router(x.clone()).oneshot(request).await.unwrap();
    let status = response.status();
    let kind = response
        .headers()
        .get("content-type")
        .map(|v| v.to_str().unwrap().to_string());
    let bytes = to_bytes(response.into_body(), 1 << 26).await.unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(
        status.is_client_error(),
        "{method} {uri} {body}: {status} {text}"
    );
    assert_eq!(
        kind.as_deref(),
        Some("application/json"),
        "{method} {uri} {body}: {text}"
    );
    let v: Value = serde_json::from_slice(&bytes)
        .unwrap_or_else(|e| panic!("{method} {uri} {body}: not JSON ({e}): {text}"));
    assert!(
        !v["error"].as_str().unwrap_or("").is_empty(),
        "{method} {uri} {body}: {v}"
    );
    assert!(v.get("key").is_some(), "{method} {uri} {body}: {v}");
    (status, v)
}

async fn call_json(x: &Arc<Explorer>, method: &str, uri: &str, body: &str) -> (StatusCode, Value) {
    let (status, bytes) = call(x, method, uri, body).await;
    let v = serde_json::from_slice(&bytes)
        .unwrap_or_else(|e| panic!("{uri}: not JSON ({e}): {}", String::from_utf8_lossy(&bytes)));
    (status, v)
}

/// Opens a session (as a new page does) and returns its id.
async fn new_session(x: &Arc<Explorer>) -> u64 {
    let (status, s) = call_json(x, "POST", "/api/session", "").await;
    assert_eq!(status, StatusCode::CREATED, "{s}");
    s["session"].as_u64().unwrap()
}

/// Waits until the session's status satisfies `done` (bounded: 2000 polls of 5 ms).
async fn wait_status(x: &Arc<Explorer>, id: u64, done: impl Fn(&Value) -> bool) -> Value {
    for _ in 0..2000 {
        let (_, s) = call_json(x, "GET", &format!("/api/status?session={id}"), "").await;
        if done(&s) {
            return s;
        }
        tokio::time::sleep(std::time::Duration::from_millis(5)).await;
    }
    panic!("session {id} never reached the state asked for");
}

/// The explorer's router on a loopback listener (for the WebSocket tests): its address and
/// the server's task.
async fn serve(
    x: &Arc<Explorer>,
) -> (
    std::net::SocketAddr,
    tokio::task::JoinHandle<std::io::Result<()>>,
) {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let app = router(x.clone());
    (
        addr,
        tokio::spawn(async move { axum::serve(listener, app).await }),
    )
}

#[tokio::test]
async fn the_page_and_its_assets_come_from_the_server_only() {
    let x = explorer(1);
    let (status, page) = call(&x, "GET", "/", "").await;
    assert_eq!(status, StatusCode::OK);
    let page = String::from_utf8(page).unwrap();
    assert!(page.contains("/assets/app.js") && page.contains("/assets/style.css"));
    for asset in ["/", "/assets/app.js", "/assets/style.css"] {
        let (status, body) = call(&x, "GET", asset, "").await;
        assert_eq!(status, StatusCode::OK, "{asset}");
        let text = String::from_utf8(body).unwrap();
        // No outside host: no absolute http(s) URL anywhere in the page or its assets.
        assert!(
            !text.contains("http://") && !text.contains("https://"),
            "{asset}"
        );
    }
    let (status, _) = call(&x, "GET", "/assets/nothing.js", "").await;
    assert_eq!(status, StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn the_scene_endpoint_gives_the_files_camera() {
    let x = explorer(1);
    let (status, s) = call_json(&x, "GET", "/api/scene", "").await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(s["camera"]["fov"], json!(40.0));
    assert_eq!(s["camera"]["eye"], json!([0.0, 0.0, 5.0]));
    assert_eq!(s["resolution"], json!([48, 32]));
    assert!(
        s["types"]
            .as_array()
            .unwrap()
            .contains(&json!("perspective"))
    );
}

#[tokio::test]
async fn bad_changes_get_a_4xx_that_names_the_key() {
    let x = explorer(1);
    for (body, status, key) in [
        (r#"{"camera": {"fov": 400}}"#, 400, Some("camera.fov")),
        (
            r#"{"camera": {"lens_radius": -1}}"#,
            400,
            Some("camera.lens_radius"),
        ),
        (
            r#"{"camera": {"focal_distance": 0}}"#,
            400,
            Some("camera.focal_distance"),
        ),
        (
            r#"{"resolution": [100000, 2]}"#,
            422,
            Some("film.resolution"),
        ),
        (
            r#"{"resolution": [3000, 3000]}"#,
            422,
            Some("film.resolution"),
        ),
        (r#"{"spp": 0}"#, 422, Some("sampler.spp")),
        (r#"{"spp": 4000000000}"#, 422, Some("sampler.spp")),
        (r#"{"spp": 5000000000}"#, 422, Some("sampler.spp")),
        // Malformed values: a 400 naming the key, not serde's message alone.
        (r#"{"spp": -1}"#, 400, Some("sampler.spp")),
        (r#"{"spp": 1.5}"#, 400, Some("sampler.spp")),
        (r#"{"spp": "4"}"#, 400, Some("sampler.spp")),
        (r#"{"camera": {"fov": 1e400}}"#, 400, Some("camera.fov")),
        (
            r#"{"camera": {"eye": [0, 0, -1e400]}}"#,
            400,
            Some("camera.eye"),
        ),
        (
            r#"{"camera": {"eye": [0, null, 1]}}"#,
            400,
            Some("camera.eye"),
        ),
        (
            r#"{"camera": {"stereo": {"interaxial": 1e400}}}"#,
            400,
            Some("camera.stereo.interaxial"),
        ),
        (r#"{"camera": 5}"#, 400, Some("camera")),
        (r#"{"resolution": [-1, 2]}"#, 400, Some("film.resolution")),
        (r#"{"resolution": [64]}"#, 400, Some("film.resolution")),
        (
            r#"{"resolution": [64, 1e400]}"#,
            400,
            Some("film.resolution"),
        ),
        (r#"{"cameraa": {}}"#, 400, Some("cameraa")),
        (r#"{"camera": {"fov": "#, 400, Some("camera.fov")),
        // No key at fault: the body is not a change at all.
        (r#"[1, 2]"#, 400, None),
        ("not json", 400, None),
    ] {
        let (got, v) = call_error(&x, "POST", "/api/view", body).await;
        assert_eq!(got.as_u16(), status, "{body}: {v}");
        assert_eq!(v["key"], json!(key), "{body}: {v}");
        if let Some(key) = key {
            assert!(v["error"].as_str().unwrap().contains(key), "{body}: {v}");
        }
    }
    let (got, v) = call_json(&x, "POST", "/api/view", r#"{"camera": {"fov": 60}}"#).await;
    assert_eq!(got, StatusCode::OK, "{v}");
    assert_eq!(v["camera"]["fov"], json!(60));
}

#[tokio::test]
async fn unknown_sessions_and_bad_queries_are_4xx_in_json_naming_the_key() {
    let x = explorer(1);
    for (method, uri, body, key) in [
        ("GET", "/api/status?session=999", "", None),
        ("POST", "/api/view?session=999", "{}", None),
        ("GET", "/api/scene.toml?session=999", "", None),
        ("GET", "/api/image.png?session=999", "", None),
        ("DELETE", "/api/session?session=999", "", None),
        ("GET", "/api/scene?session=nosuch", "", Some("session")),
        ("GET", "/api/status?session=nosuch", "", Some("session")),
        ("POST", "/api/view?session=nosuch", "{}", Some("session")),
        (
            "POST",
            "/api/focus?session=1.5",
            r#"{"x": 1, "y": 1}"#,
            Some("session"),
        ),
        ("GET", "/api/image.exr?session=-1", "", Some("session")),
        ("DELETE", "/api/session?session=", "", Some("session")),
        ("DELETE", "/api/session", "", Some("session")),
        ("GET", "/api/status", "", Some("session")),
        ("GET", "/api/image.png", "", Some("session")),
        ("GET", "/api/coords?x=abc&y=1", "", Some("x")),
        ("GET", "/api/coords?x=NaN&y=1", "", Some("x")),
        ("GET", "/api/coords?x=1", "", Some("y")),
        (
            "GET",
            "/api/coords?x=1&y=2&session=two",
            "",
            Some("session"),
        ),
        ("POST", "/api/focus", r#"{"x": 1}"#, Some("y")),
        ("POST", "/api/focus", r#"{"x": 1e400, "y": 3}"#, Some("x")),
        ("POST", "/api/focus", r#"{"x": "1", "y": 3}"#, Some("x")),
        (
            "POST",
            "/api/focus",
            r#"{"x": 1, "y": 3, "z": 0}"#,
            Some("z"),
        ),
        ("POST", "/api/focus", r#"{"x": -5, "y": 3}"#, None),
        ("POST", "/api/focus", r#"{"x": 1e30, "y": 3}"#, None),
        ("POST", "/api/focus", "[1, 2]", None),
        (
            "GET",
            "/api/postprocess.png?effect=blur",
            "",
            Some("effect"),
        ),
        ("GET", "/api/postprocess.png", "", Some("effect")),
        // Not a WebSocket handshake; a session named or not.
        ("GET", "/api/ws", "", None),
        ("GET", "/api/ws?session=nosuch", "", None),
    ] {
        let (_, v) = call_error(&x, method, uri, body).await;
        assert_eq!(v["key"], json!(key), "{method} {uri} {body}: {v}");
    }
    // A refused handshake opens no session.
    assert_eq!(x.session_count(), 0);
}

#[tokio::test]
async fn coordinates_follow_the_space_conventions() {
    let x = explorer(1);
    // The film's centre: NDC (0.5, 0.5), on the optical axis in screen and camera space.
    let (status, c) = call_json(&x, "GET", "/api/coords?x=24&y=16", "").await;
    assert_eq!(status, StatusCode::OK, "{c}");
    let p = &c["projective"];
    let f = |v: &Value| v.as_f64().unwrap();
    assert!((f(&p["ndc"][0]) - 0.5).abs() < 1e-6 && (f(&p["ndc"][1]) - 0.5).abs() < 1e-6);
    assert!(f(&p["screen"][0]).abs() < 1e-5 && f(&p["screen"][1]).abs() < 1e-5);
    assert!(f(&p["camera"][0]).abs() < 1e-5 && f(&p["camera"][1]).abs() < 1e-5);
    // The centre ray looks from the eye towards the target, -z.
    assert!((f(&c["ray"]["direction"][2]) + 1.0).abs() < 1e-5, "{c}");
    // The top-left corner: NDC (0, 0); screen y up, so its screen y is positive.
    let (_, c) = call_json(&x, "GET", "/api/coords?x=0&y=0", "").await;
    let p = &c["projective"];
    assert!(f(&p["ndc"][0]).abs() < 1e-6 && f(&p["ndc"][1]).abs() < 1e-6);
    assert!(f(&p["screen"][0]) < 0.0 && f(&p["screen"][1]) > 0.0, "{c}");
}

/// With a crop window the page's image starts at the window's first pixel: a position in it
/// is that much further into the film. The scene's film is 48 x 32 and the window its lower
/// right quarter, so the image's (0.5, 0.5) is raster (24.5, 16.5), half a pixel off the
/// film's centre. A pixel there spans 2 tan(20 deg) / 32 = 0.022748 on the plane z = 1, so the
/// ray is (0.011374, -0.011374, -1) from the eye at z = 5; it meets the unit sphere at the
/// origin where (5 - t)^2 + t^2 s = 1, s = 2 (0.011374)^2 = 0.00025874:
/// t = (10 - sqrt(4 - 96 s)) / (2 (1 + s)) = 4.002075, the depth. The image's (22.5, 14.5) is
/// raster (46.5, 30.5), on the wall at z = -2: depth 7 for any ray. Without the offset, the
/// first position is raster (0.5, 0.5), off the crop window.
#[tokio::test]
async fn a_cropped_views_positions_are_offset_into_the_film() {
    let text = scene_text(1).replace(
        "resolution = [48, 32]",
        "resolution = [48, 32]\ncrop = [0.5, 1.0, 0.5, 1.0]",
    );
    let view = View::parse(&PathBuf::from("explore-test.toml"), &text).unwrap();
    let x = Explorer::new(view, Some(1));
    let id = new_session(&x).await;
    wait_status(&x, id, |s| s["passes_done"] == json!(1)).await;
    let (status, c) = call_json(
        &x,
        "GET",
        &format!("/api/coords?session={id}&x=1.5&y=2.5"),
        "",
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{c}");
    assert_eq!(c["raster"], json!([25.5, 18.5]), "{c}");
    for ((px, py), depth) in [((0.5, 0.5), 4.002075), ((22.5, 14.5), 7.0)] {
        let (got, _) = focus_at(&x, id, px, py).await;
        assert!(
            (got - depth).abs() < 1e-4,
            "({px}, {py}): depth {got}, expected {depth}"
        );
    }
    // Off the 24 x 16 image: refused in the image's terms, for the overlay too.
    for (method, uri, body) in [
        (
            "POST",
            format!("/api/focus?session={id}"),
            r#"{"x": 30, "y": 10}"#,
        ),
        ("GET", format!("/api/coords?session={id}&x=10&y=20"), ""),
    ] {
        let (status, v) = call_error(&x, method, &uri, body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{uri}: {v}");
        let message = v["error"].as_str().unwrap();
        assert!(
            message.contains("off the image [0, 24) x [0, 16)"),
            "{uri}: {message}"
        );
    }
    // A cropped pair's image is the two eyes' windows side by side: 2 x 24 by 16.
    let text = format!("{text}[camera.stereo]\ninteraxial = 0.1\nconvergence = 5.0\n");
    let view = View::parse(&PathBuf::from("explore-test.toml"), &text).unwrap();
    let x = Explorer::new(view, Some(1));
    let (status, v) = call_json(&x, "GET", "/api/scene", "").await;
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["stereo"]["image"], json!([48, 16]), "{v}");
}

#[tokio::test]
async fn a_session_renders_saves_and_focuses() {
    let x = explorer(2);
    let id = new_session(&x).await;
    wait_status(&x, id, |s| s["passes_done"] == json!(2)).await;

    let (status, png) = call(&x, "GET", &format!("/api/image.png?session={id}"), "").await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let (status, exr) = call(&x, "GET", &format!("/api/image.exr?session={id}"), "").await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01]);

    // Autofocus on the sphere's front (depth 4) and on the wall (depth 7).
    for ((px, py), depth) in [((24.0, 16.0), 4.0), ((1.5, 1.5), 7.0)] {
        let (got, v) = focus_at(&x, id, px, py).await;
        assert!(
            (got - depth).abs() < 1e-3,
            "({px}, {py}): depth {got}, expected {depth}"
        );
        assert_eq!(v["camera"]["focal_distance"], v["depth"]);
    }

    // A change, then the saved scene file holds it and parses as a scene.
    let (status, _) = call_json(
        &x,
        "POST",
        &format!("/api/view?session={id}"),
        r#"{"camera": {"lens_radius": 0.125}}"#,
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    let (_, toml) = call(&x, "GET", &format!("/api/scene.toml?session={id}"), "").await;
    let saved = View::parse(
        &PathBuf::from("saved.toml"),
        std::str::from_utf8(&toml).unwrap(),
    )
    .expect("the saved view is a valid scene");
    assert_eq!(saved.description().camera.lens.radius, 0.125);
    assert!((saved.description().camera.lens.focal_distance - 7.0).abs() < 1e-3);

    for effect in ["dof", "motion"] {
        let uri = format!("/api/postprocess.png?session={id}&effect={effect}");
        let (status, png) = call(&x, "GET", &uri, "").await;
        assert_eq!(
            status,
            StatusCode::OK,
            "{effect}: {}",
            String::from_utf8_lossy(&png)
        );
        assert_eq!(&png[..4], b"\x89PNG");
    }

    let (status, _) = call(&x, "DELETE", &format!("/api/session?session={id}"), "").await;
    assert_eq!(status, StatusCode::NO_CONTENT);
    assert_eq!(x.session_count(), 0);
}

#[tokio::test]
async fn a_change_cancels_the_render_in_flight_and_restarts_at_pass_one() {
    // Far more passes than can finish during the test: only a cancel stops the first render.
    let session = Session::start(view(60_000), Some(1)).unwrap();
    let mut frames = session.frames();
    frames
        .wait_for(|f| f.as_ref().is_some_and(|f| f.generation == 0))
        .await
        .unwrap();
    let mut change = ViewChange::default();
    change.camera.insert("lens_radius".into(), json!(0.2));
    let (generation, _) = session.change(&change).unwrap();
    assert_eq!(generation, 1);
    let first = frames
        .wait_for(|f| f.as_ref().is_some_and(|f| f.generation == 1))
        .await
        .unwrap()
        .clone()
        .unwrap();
    assert!(first.pass >= 1);
    let status = session.status();
    // The new view starts from scratch: its first frame held one pass.
    assert_eq!(status.first_pass, 1, "{status:?}");
    assert_eq!(status.renders_started, 2, "{status:?}");
    assert_eq!(status.renders_cancelled, 1, "{status:?}");
    assert!(status.renders_running <= 1, "{status:?}");

    // A refused change leaves the view and the render alone.
    let mut bad = ViewChange::default();
    bad.camera.insert("fov".into(), json!(-3));
    assert!(session.change(&bad).is_err());
    assert_eq!(session.status().generation, 1);
    assert_eq!(session.view().description().camera.lens.radius, 0.2);
}

#[tokio::test]
async fn many_quick_changes_leave_one_render() {
    let session = Session::start(view(60_000), Some(1)).unwrap();
    let mut frames = session.frames();
    for i in 0..50 {
        let mut change = ViewChange::default();
        change.camera.insert("fov".into(), json!(20.0 + i as f64));
        session.change(&change).unwrap();
        assert!(session.status().renders_running <= 1);
    }
    frames
        .wait_for(|f| f.as_ref().is_some_and(|f| f.generation == 50))
        .await
        .unwrap();
    let status = session.status();
    assert_eq!(status.first_pass, 1, "{status:?}");
    assert!(status.renders_running <= 1, "{status:?}");
    // Coalesced: far fewer renders than changes were started.
    assert!(status.renders_started <= 51, "{status:?}");
}

#[tokio::test]
async fn the_websocket_streams_frames_and_takes_changes() {
    let x = explorer(4);
    let (addr, server) = serve(&x).await;
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/api/ws"))
        .await
        .unwrap();

    let text = |m: Message| -> Value {
        match m {
            Message::Text(t) => serde_json::from_str(t.as_str()).unwrap(),
            other => panic!("expected text, got {other:?}"),
        }
    };
    let hello = text(ws.next().await.unwrap().unwrap());
    assert_eq!(hello["type"], json!("hello"));
    assert_eq!(x.session_count(), 1);

    // Frames of generation 0 until a change.
    let frame = loop {
        if let Message::Binary(b) = ws.next().await.unwrap().unwrap() {
            break b;
        }
    };
    let word = |b: &[u8], i: usize| u32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    assert_eq!(word(&frame, 0), 0);
    assert!(word(&frame, 1) >= 1 && word(&frame, 2) == 4);
    assert_eq!(&frame[12..16], b"\x89PNG");

    ws.send(Message::Text(r#"{"camera": {"fov": 400}}"#.into()))
        .await
        .unwrap();
    ws.send(Message::Text(r#"{"spp": -1}"#.into()))
        .await
        .unwrap();
    ws.send(Message::Text(r#"{"camera": {"fov": 1e400}}"#.into()))
        .await
        .unwrap();
    ws.send(Message::Text(r#"{"camera": {"fov": 25}}"#.into()))
        .await
        .unwrap();
    let mut replies = Vec::new();
    let mut new_frame = None;
    while replies.len() < 4 || new_frame.is_none() {
        match ws.next().await.unwrap().unwrap() {
            Message::Text(t) => replies.push(serde_json::from_str::<Value>(t.as_str()).unwrap()),
            Message::Binary(b) if word(&b, 0) == 1 => new_frame = Some(b),
            _ => {}
        }
    }
    assert_eq!(replies[0]["type"], json!("error"));
    assert_eq!(replies[0]["key"], json!("camera.fov"));
    assert_eq!(replies[1]["type"], json!("error"));
    assert_eq!(replies[1]["key"], json!("sampler.spp"), "{}", replies[1]);
    assert_eq!(replies[2]["type"], json!("error"));
    assert_eq!(replies[2]["key"], json!("camera.fov"), "{}", replies[2]);
    assert_eq!(replies[3]["type"], json!("view"));
    assert_eq!(replies[3]["generation"], json!(1));
    assert_eq!(replies[3]["camera"]["fov"], json!(25));
    assert!(new_frame.is_some());

    // Garbage does not close the socket; it gets an error reply.
    ws.send(Message::Text("not json".into())).await.unwrap();
    loop {
        if let Message::Text(t) = ws.next().await.unwrap().unwrap() {
            assert_eq!(text(Message::Text(t))["type"], json!("error"));
            break;
        }
    }

    ws.close(None).await.unwrap();
    // The page's session ends with its socket.
    for _ in 0..2000 {
        if x.session_count() == 0 {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(5)).await;
    }
    assert_eq!(x.session_count(), 0);
    server.abort();
}

#[tokio::test]
async fn a_socket_opened_after_the_last_pass_still_gets_the_frame() {
    let x = explorer(2);
    let id = new_session(&x).await;
    // The view is rendered to its end before any socket listens.
    wait_status(&x, id, |s| s["passes_done"] == json!(2)).await;
    let (addr, server) = serve(&x).await;
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/api/ws?session={id}"))
        .await
        .unwrap();
    // The hello, then the finished frame (a bound, so a frame that never comes fails the
    // test instead of hanging it).
    let frame = tokio::time::timeout(std::time::Duration::from_secs(30), async {
        loop {
            if let Message::Binary(b) = ws.next().await.unwrap().unwrap() {
                break b;
            }
        }
    })
    .await
    .expect("the finished view's frame reaches a socket opened after it");
    let word = |i: usize| u32::from_le_bytes(frame[i * 4..i * 4 + 4].try_into().unwrap());
    assert_eq!((word(0), word(1), word(2)), (0, 2, 2));
    assert_eq!(&frame[12..16], b"\x89PNG");
    server.abort();
}

#[tokio::test]
async fn pages_past_the_limit_are_refused_and_the_server_keeps_answering() {
    let x = explorer(4);
    let mut ids = Vec::new();
    for _ in 0..obscura_explore::MAX_SESSIONS {
        ids.push(new_session(&x).await);
    }
    let (status, v) = call_json(&x, "POST", "/api/session", "").await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{v}");
    assert_eq!(v["key"], json!("session"));
    // With every session rendering, the API still answers, and each session's view is its own.
    let (status, _) = call_json(&x, "GET", "/api/scene", "").await;
    assert_eq!(status, StatusCode::OK);
    let (status, _) = call_json(
        &x,
        "POST",
        &format!("/api/view?session={}", ids[0]),
        r#"{"camera": {"fov": 30}}"#,
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    let (_, other) = call_json(&x, "GET", &format!("/api/scene?session={}", ids[1]), "").await;
    assert_eq!(other["camera"]["fov"], json!(40.0));
    for id in ids {
        let (status, _) = call(&x, "DELETE", &format!("/api/session?session={id}"), "").await;
        assert_eq!(status, StatusCode::NO_CONTENT);
    }
    let (status, _) = call_json(&x, "POST", "/api/session", "").await;
    assert_eq!(status, StatusCode::CREATED);
}

/// The scene of `scene_text` with its film and spp replaced.
fn view_with(resolution: [u32; 2], spp: u32) -> View {
    let text = scene_text(spp).replace(
        "resolution = [48, 32]",
        &format!("resolution = [{}, {}]", resolution[0], resolution[1]),
    );
    View::parse(&PathBuf::from("explore-test.toml"), &text).unwrap()
}

/// The width and height in a PNG's header.
fn png_size(png: &[u8]) -> [u32; 2] {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let word = |i: usize| u32::from_be_bytes(png[i..i + 4].try_into().unwrap());
    [word(16), word(20)]
}

#[tokio::test]
async fn a_scene_file_beyond_the_limits_is_previewed_at_them_and_says_so() {
    let x = Explorer::new(view_with([10_000, 10_000], 10_000_000), Some(1));
    let (status, s) = call_json(&x, "GET", "/api/scene", "").await;
    assert_eq!(status, StatusCode::OK, "{s}");
    assert_eq!(s["resolution"], json!([2048, 2048]), "{s}");
    assert_eq!(s["spp"], json!(65_536), "{s}");
    assert_eq!(s["clamped"][0]["key"], json!("film.resolution"), "{s}");
    assert_eq!(s["clamped"][0]["file"], json!([10_000, 10_000]), "{s}");
    assert_eq!(s["clamped"][1]["key"], json!("sampler.spp"), "{s}");
    assert_eq!(s["clamped"][1]["file"], json!(10_000_000), "{s}");

    let (status, v) = call_json(&x, "POST", "/api/session", "").await;
    assert_eq!(status, StatusCode::CREATED, "{v}");
    assert_eq!(v["resolution"], json!([2048, 2048]), "{v}");
    assert_eq!(v["clamped"], s["clamped"]);
    let id = v["session"].as_u64().unwrap();
    // The camera's keys still change (the file's film is not held against the page)...
    let (status, v) = call_json(
        &x,
        "POST",
        &format!("/api/view?session={id}"),
        r#"{"camera": {"fov": 30}}"#,
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["resolution"], json!([2048, 2048]), "{v}");
    // ...a page asking for more than the limits is still refused...
    let uri = format!("/api/view?session={id}");
    let body = r#"{"resolution": [10000, 10000]}"#;
    let unprocessable = StatusCode::UNPROCESSABLE_ENTITY;
    assert_refused(&x, ("POST", &uri, body), unprocessable, "film.resolution").await;
    // ...and the saved scene keeps the file's own film and spp.
    let (_, toml) = call(&x, "GET", &format!("/api/scene.toml?session={id}"), "").await;
    let saved: toml::Table = std::str::from_utf8(&toml).unwrap().parse().unwrap();
    assert_eq!(
        saved["film"]["resolution"],
        toml::Value::try_from([10_000, 10_000]).unwrap()
    );
    assert_eq!(saved["sampler"]["spp"], toml::Value::Integer(10_000_000));
    let (status, _) = call(&x, "DELETE", &format!("/api/session?session={id}"), "").await;
    assert_eq!(status, StatusCode::NO_CONTENT);

    // What renders is the preview: its frames are 2048 x 2048 of 65536 passes.
    let session = Session::start(view_with([10_000, 10_000], 10_000_000), Some(1)).unwrap();
    let frame = session
        .frames()
        .wait_for(|f| f.is_some())
        .await
        .unwrap()
        .clone()
        .unwrap();
    assert_eq!(frame.passes, 65_536);
    assert_eq!(png_size(&frame.png), [2048, 2048]);
}

/// A stereo pair of a small white sphere on black, laid out as `layout`: the rig at z = 5
/// looking along -z (fov 40 across the 48 rows), interaxial 1, convergence 10; the sphere
/// (radius 0.5) at the origin, 5 in front of the rig. The albedo integrator makes it 1 where
/// the sphere is and 0 elsewhere, so its centroid is sharp from few samples.
fn stereo_text(layout: &str) -> String {
    format!(
        r#"
[film]
resolution = [64, 48]
[sampler]
type = "sobol"
spp = 4
[integrator]
type = "albedo"
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[camera.stereo]
interaxial = 1.0
convergence = 10.0
layout = "{layout}"
[materials.white]
type = "diffuse"
reflectance = [1.0, 1.0, 1.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.5
material = "white"
"#
    )
}

fn stereo_view(layout: &str) -> View {
    View::parse(&PathBuf::from("stereo-test.toml"), &stereo_text(layout)).unwrap()
}

/// The two eyes as `obscura render` renders a stereo scene: each eye's description from
/// `stereo_eyes`, built and rendered to its last pass, independently of the explorer.
fn eyes_rendered(view: &View) -> [obscura_render::Image; 2] {
    let [left, right] = view.description().stereo_eyes().expect("a stereo pair");
    [left, right].map(|d| {
        let scene = obscura_render::RenderScene::build(d).unwrap();
        obscura_render::render(&scene, Default::default())
            .unwrap()
            .film
            .resolve()
    })
}

/// The session's last frame of its first view: waits for it (no clock: the frames' channel).
async fn finished(session: &Session) -> obscura_explore::Frame {
    session
        .frames()
        .wait_for(|f| f.as_ref().is_some_and(|f| f.pass == f.passes))
        .await
        .unwrap()
        .clone()
        .unwrap()
}

/// The columns `x0..x1` of `image` as an image of their own.
fn columns(image: &obscura_render::Image, x0: u32, x1: u32) -> obscura_render::Image {
    obscura_render::Image {
        width: x1 - x0,
        height: image.height,
        pixels: (0..image.height)
            .flat_map(|y| (x0..x1).map(move |x| image.pixel(x, y)))
            .collect(),
    }
}

/// The centroid of a channel's values: (x, y) in raster units (pixel centres at + 0.5).
fn centroid(image: &obscura_render::Image, channel: usize) -> (f64, f64) {
    let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
    for y in 0..image.height {
        for x in 0..image.width {
            let v = f64::from(image.pixel(x, y)[channel]);
            sx += v * (f64::from(x) + 0.5);
            sy += v * (f64::from(y) + 0.5);
            s += v;
        }
    }
    assert!(s > 0.0, "nothing bright in the image");
    (sx / s, sy / s)
}

/// Where each eye sees the sphere's centre, worked by hand (docs/cameras.md, off-axis
/// stereo): an eye at offset `e` along camera +x (left `-b/2`, right `+b/2`, `b` = 1) sees the
/// centre, 5 in front of the rig on its axis, at screen x `s (0 - e) / 5`, and its window is
/// shifted by `-s e / C` (`C` = 10), so relative to the window's centre it is at
/// `-s e (1/5 - 1/10)`, with `s = 1 / tan(20 deg) = 2.7475`. A screen unit is 24 pixels (the
/// window spans [-1, 1] over 48 rows), so the left eye sees it at raster x
/// `32 + 24 * 2.7475 * 0.5 * 0.1 = 35.297`, the right at `28.703`: a parallax of 6.594
/// pixels, the left image to the right of the right one (the sphere is nearer than the
/// convergence plane). Both at raster y 24.
const LEFT_X: f64 = 35.297;
const RIGHT_X: f64 = 28.703;

#[tokio::test]
async fn a_side_by_side_pair_is_the_command_lines_pair_with_the_parallax_of_its_rig() {
    let view = stereo_view("side_by_side");
    let session = Session::start(view.clone(), Some(1)).unwrap();
    let frame = finished(&session).await;
    // The page's image is twice as wide: the eyes side by side.
    assert_eq!(png_size(&frame.png), [128, 48]);
    let (image, _, passes) = session.latest_image().unwrap();
    assert_eq!((image.width, image.height, passes), (128, 48, 4));
    let (left, right) = (columns(&image, 0, 64), columns(&image, 64, 128));

    // The parallax the rig's geometry predicts.
    let (lx, ly) = centroid(&left, 0);
    let (rx, ry) = centroid(&right, 0);
    assert!(
        (lx - LEFT_X).abs() < 0.1 && (ly - 24.0).abs() < 0.1,
        "left eye: sphere at ({lx:.3}, {ly:.3}), expected ({LEFT_X}, 24)"
    );
    assert!(
        (rx - RIGHT_X).abs() < 0.1 && (ry - 24.0).abs() < 0.1,
        "right eye: sphere at ({rx:.3}, {ry:.3}), expected ({RIGHT_X}, 24)"
    );

    // Pass by pass, each eye's film is exact: the halves are the command line's eyes bit for
    // bit.
    let [want_left, want_right] = eyes_rendered(&view);
    assert!(
        left == want_left,
        "the left half is not the left eye's render"
    );
    assert!(
        right == want_right,
        "the right half is not the right eye's render"
    );
    let (eyes, layout, _, _) = session.latest_eyes().unwrap();
    assert_eq!(layout, obscura_render::StereoLayout::SideBySide);
    assert!(eyes[0] == want_left && eyes[1] == want_right);
}

#[tokio::test]
async fn an_anaglyph_takes_red_from_the_left_eye_and_cyan_from_the_right() {
    let view = stereo_view("anaglyph");
    let session = Session::start(view.clone(), Some(1)).unwrap();
    let frame = finished(&session).await;
    assert_eq!(png_size(&frame.png), [64, 48]);
    let (image, _, _) = session.latest_image().unwrap();
    let [left, right] = eyes_rendered(&view);
    for y in 0..48 {
        for x in 0..64 {
            let (a, l, r) = (image.pixel(x, y), left.pixel(x, y), right.pixel(x, y));
            // Red: the left eye's luminance (Rec. 709); green and blue: the right eye's.
            let luminance = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
            assert!((a[0] - luminance).abs() < 1e-6, "({x}, {y}): {a:?} {l:?}");
            assert_eq!([a[1], a[2]], [r[1], r[2]], "({x}, {y})");
            assert!((a[3] - 0.5 * (l[3] + r[3])).abs() < 1e-6, "({x}, {y})");
        }
    }
    // So the red image of the sphere is where the left eye sees it, the cyan where the right.
    let (red, _) = centroid(&image, 0);
    let (green, _) = centroid(&image, 1);
    assert!(
        (red - LEFT_X).abs() < 0.1 && (green - RIGHT_X).abs() < 0.1,
        "red at {red:.3}, cyan at {green:.3}"
    );
}

#[tokio::test]
async fn a_stereo_pairs_api_saves_and_points_as_the_command_line_would() {
    let x = Explorer::new(stereo_view("separate"), Some(1));
    let (_, s) = call_json(&x, "GET", "/api/scene", "").await;
    assert_eq!(
        s["stereo"],
        json!({"layout": "separate", "shown": "side_by_side", "image": [128, 48]})
    );
    let id = new_session(&x).await;
    wait_status(&x, id, |s| s["passes_done"] == json!(4)).await;

    // Separate: one file per eye, as `obscura render` writes NAME-left and NAME-right; the
    // request names the eye.
    let png = format!("/api/image.png?session={id}");
    assert_refused(
        &x,
        ("GET", &png, ""),
        StatusCode::UNPROCESSABLE_ENTITY,
        "eye",
    )
    .await;
    let exr = format!("/api/image.exr?session={id}&eye=middle");
    assert_refused(&x, ("GET", &exr, ""), StatusCode::BAD_REQUEST, "eye").await;
    let [left, right] = eyes_rendered(&stereo_view("separate"));
    for (eye, image) in [("left", &left), ("right", &right)] {
        let uri = format!("/api/image.png?session={id}&eye={eye}");
        let response = router(x.clone())
            .oneshot(Request::get(&uri).body(Body::empty()).unwrap())
            .await
            .unwrap();
        assert_eq!(response.status(), StatusCode::OK);
        let disposition = response.headers()["content-disposition"].to_str().unwrap();
        assert_eq!(
            disposition,
            format!("attachment; filename=\"view-{eye}.png\"")
        );
        let png = to_bytes(response.into_body(), 1 << 26).await.unwrap();
        assert!(
            png.as_ref() == cli_png(image),
            "the {eye} eye's PNG is not the file `obscura render` writes of its render"
        );
        let (status, exr) = call(
            &x,
            "GET",
            &format!("/api/image.exr?session={id}&eye={eye}"),
            "",
        )
        .await;
        assert_eq!(status, StatusCode::OK);
        assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01]);
    }

    // Autofocus: each half of the image is its eye's film. Either eye's ray through the
    // sphere centre's image runs sqrt(5^2 + 0.5^2) = 5.02494 to the centre and meets the
    // sphere 0.5 sooner, at camera z 4.52494 * 5 / 5.02494 = 4.50248.
    let mut depths = Vec::new();
    for px in [LEFT_X, 64.0 + RIGHT_X] {
        let (status, v) = call_json(
            &x,
            "POST",
            &format!("/api/focus?session={id}"),
            &json!({"x": px, "y": 24.0}).to_string(),
        )
        .await;
        assert_eq!(status, StatusCode::OK, "{v}");
        depths.push(v["depth"].as_f64().unwrap());
    }
    assert!(
        (depths[0] - depths[1]).abs() < 1e-4 && (depths[0] - 4.50248).abs() < 1e-3,
        "{depths:?}"
    );
    // The sphere's image has a raster radius of tan(asin(0.1)) / tan(20 deg) * 24 = 6.63:
    // 5 pixels right of the left eye's centre is on it in the left half, but in the right
    // half it is off the right eye's image (and the centre's); past the image, nothing.
    for (px, py) in [(64.0 + LEFT_X + 5.0, 24.0), (130.0, 24.0)] {
        let (status, v) = call_error(
            &x,
            "POST",
            &format!("/api/focus?session={id}"),
            &json!({"x": px, "y": py}).to_string(),
        )
        .await;
        assert_eq!(
            status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "({px}, {py}): {v}"
        );
    }
    let (status, v) = call_json(
        &x,
        "POST",
        &format!("/api/focus?session={id}"),
        &json!({"x": LEFT_X + 5.0, "y": 24.0}).to_string(),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{v}");

    // The coordinates overlay names the eye and gives its film's raster position.
    let (_, c) = call_json(
        &x,
        "GET",
        &format!("/api/coords?session={id}&x=96&y=24"),
        "",
    )
    .await;
    assert_eq!(c["eye"], json!("right"), "{c}");
    assert_eq!(c["raster"], json!([32.0, 24.0]), "{c}");
    let (_, c) = call_json(&x, "GET", "/api/coords?x=24&y=16", "").await;
    assert_eq!(c["eye"], json!("left"), "{c}");

    // The post-process comparison shows the pair as the page does.
    let (status, png) = call(
        &x,
        "GET",
        &format!("/api/postprocess.png?session={id}&effect=dof"),
        "",
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&png));
    assert_eq!(png_size(&png), [128, 48]);

    // The saved scene keeps the pair, for `obscura render` to write as its layout says.
    let (_, toml) = call(&x, "GET", &format!("/api/scene.toml?session={id}"), "").await;
    let saved = View::parse(
        &PathBuf::from("saved.toml"),
        std::str::from_utf8(&toml).unwrap(),
    )
    .unwrap();
    let stereo = saved.description().camera.stereo.unwrap();
    assert_eq!(stereo.layout, obscura_render::StereoLayout::Separate);
    assert_eq!(stereo.rig.convergence, 10.0);

    // Side by side and anaglyph save the composed image; a single view has no eyes.
    let (_, v) = call_json(
        &x,
        "POST",
        &format!("/api/view?session={id}"),
        r#"{"camera": {"stereo": {"interaxial": 1.0, "convergence": 10.0, "layout": "side_by_side"}}}"#,
    )
    .await;
    assert_eq!(v["stereo"]["image"], json!([128, 48]), "{v}");
    let generation = v["generation"].clone();
    wait_status(&x, id, |s| {
        s["frame_generation"] == generation && s["passes_done"] == json!(4)
    })
    .await;
    let (status, png) = call(&x, "GET", &format!("/api/image.png?session={id}"), "").await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(png_size(&png), [128, 48]);
    let (_, v) = call_json(
        &x,
        "POST",
        &format!("/api/view?session={id}"),
        r#"{"camera": {"stereo": null}}"#,
    )
    .await;
    assert_eq!(v["stereo"], Json::Null, "{v}");
    let generation = v["generation"].clone();
    wait_status(&x, id, |s| {
        s["frame_generation"] == generation && s["passes_done"] == json!(4)
    })
    .await;
    let png = format!("/api/image.png?session={id}&eye=left");
    assert_refused(
        &x,
        ("GET", &png, ""),
        StatusCode::UNPROCESSABLE_ENTITY,
        "eye",
    )
    .await;
    let (_, c) = call_json(
        &x,
        "GET",
        &format!("/api/coords?session={id}&x=96&y=24"),
        "",
    )
    .await;
    assert_eq!(c["eye"], Json::Null, "{c}");
}

#[tokio::test]
async fn a_stereo_scene_beyond_the_limits_counts_its_eyes_twice() {
    let text =
        stereo_text("side_by_side").replace("resolution = [64, 48]", "resolution = [2048, 2048]");
    let x = Explorer::new(
        View::parse(&PathBuf::from("stereo-test.toml"), &text).unwrap(),
        Some(1),
    );
    let (_, s) = call_json(&x, "GET", "/api/scene", "").await;
    // Two films of 1448 x 1448 fit in 2048 x 2048 pixels; the preview is 2896 wide.
    assert_eq!(s["resolution"], json!([1448, 1448]), "{s}");
    assert_eq!(s["stereo"]["image"], json!([2896, 1448]), "{s}");
    assert_eq!(s["clamped"][0]["key"], json!("film.resolution"), "{s}");
    assert!(
        s["clamped"][0]["message"]
            .as_str()
            .unwrap()
            .contains("per eye"),
        "{s}"
    );
    let body = r#"{"resolution": [1449, 1449]}"#;
    let unprocessable = StatusCode::UNPROCESSABLE_ENTITY;
    assert_refused(
        &x,
        ("POST", "/api/view", body),
        unprocessable,
        "film.resolution",
    )
    .await;
}
