//! The explorer's HTTP and WebSocket API, driven through the router (no sockets) and, for the
//! WebSocket, through a real loopback listener.

use axum::body::{Body, to_bytes};
use axum::http::{Request, StatusCode};
use futures_util::{SinkExt, StreamExt};
use obscura_explore::{Explorer, Session, View, ViewChange, router};
use serde_json::{Value, json};
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
        let (status, v) = call_json(
            &x,
            "POST",
            &format!("/api/focus?session={id}"),
            &json!({"x": px, "y": py}).to_string(),
        )
        .await;
        assert_eq!(status, StatusCode::OK, "{v}");
        let got = v["depth"].as_f64().unwrap();
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
    let (status, v) = call_error(
        &x,
        "POST",
        &format!("/api/view?session={id}"),
        r#"{"resolution": [10000, 10000]}"#,
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{v}");
    assert_eq!(v["key"], json!("film.resolution"));
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
