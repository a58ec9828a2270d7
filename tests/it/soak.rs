//! The short soak test (tests/soak.sh is the long one, run by hand): a render interrupted with
//! SIGINT five times at different moments, resumed from its checkpoint each time, ends with
//! the bytes of the render that ran straight through, and leaves no temporary file behind.

use super::robust::{names_in, send, wait_until};
use super::{obscura, root, scratch};
use obscura_render::Checkpoint;
use std::path::Path;
use std::process::Stdio;

const SPP: &str = "200";

fn args<'a>(scene: &'a str, out: &'a Path) -> Vec<String> {
    [
        "render",
        scene,
        "-o",
        out.to_str().unwrap(),
        "--resolution",
        "48x32",
        "--spp",
        SPP,
        "--threads",
        "2",
    ]
    .map(String::from)
    .to_vec()
}

fn passes_in(checkpoint: &Path) -> u32 {
    Checkpoint::load(checkpoint).map_or(0, |c| c.passes_done)
}

#[test]
fn five_interrupts_and_resumes_equal_the_straight_render() {
    let dir = scratch("soak");
    let scene = root().join("scenes/spheres-thin-lens.toml");
    let scene = scene.to_str().unwrap();

    let straight = dir.join("straight.exr");
    let status = obscura().args(args(scene, &straight)).output().unwrap();
    assert!(status.status.success(), "{status:?}");

    let out = dir.join("out.exr");
    let checkpoint = dir.join("soak.ckpt");
    let mut interrupted = 0;
    // Each cycle waits for a different number of new passes (0 to 3) before the signal.
    for wait_passes in [1, 0, 3, 2, 1] {
        let before = passes_in(&checkpoint);
        let mut cmd = obscura();
        cmd.args(args(scene, &out))
            .args(["--checkpoint", checkpoint.to_str().unwrap()])
            .args(["--checkpoint-every", "0"]);
        if checkpoint.exists() {
            cmd.args(["--resume", checkpoint.to_str().unwrap()]);
        }
        let mut child = cmd
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // A checkpoint newer than `before` means the signal handlers are installed.
        wait_until("the render has saved new passes", || {
            passes_in(&checkpoint) > before + wait_passes || child.try_wait().unwrap().is_some()
        });
        if child.try_wait().unwrap().is_none() {
            send(&child, "INT");
        }
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        match output.status.code() {
            Some(130) => interrupted += 1,
            Some(0) => break,
            other => panic!("exit {other:?}: {stderr}"),
        }
        // The interrupted run saved at least the passes the test waited for.
        assert!(passes_in(&checkpoint) > before + wait_passes, "{stderr}");
    }
    assert!(
        interrupted >= 3,
        "the render finished before it was interrupted three times"
    );

    // The last run goes to the end from the checkpoint.
    let status = obscura()
        .args(args(scene, &out))
        .args(["--checkpoint", checkpoint.to_str().unwrap()])
        .args(["--resume", checkpoint.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&straight).unwrap()
    );
    // The first interrupted run wrote its partial image as out.exr; the later ones found an
    // image there and wrote theirs beside it. Nothing else was left.
    assert_eq!(
        names_in(&dir),
        ["out.exr", "out.partial.exr", "soak.ckpt", "straight.exr"]
    );
}
