//! The Kubernetes recipe (deploy/kubernetes/), checked without a cluster: the manifests are
//! parsed, their wiring checked (an Indexed Job whose completions equal the N of `--slice`,
//! both Jobs on the one shared claim, every path under its mount), and then their commands are
//! run as the pods would run them, with the mount mapped to a scratch folder: every completion
//! index's render, then the merge, whose image must equal a one-process render bit for bit.
//! This proves the commands use flags the CLI accepts and that the paths meet.

use super::{obscura, root, scratch};
use std::path::{Path, PathBuf};
use yaml_rust2::{Yaml, YamlLoader};

/// A small scene for the manifests' fixed scene path: its own resolution and spp, so the
/// manifests' commands run as written.
const SCENE: &str = r#"
[film]
resolution = [24, 18]
[sampler]
spp = 6
[integrator]
type = "path"
max_depth = 3
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 60.0
[materials.wall]
type = "diffuse"
reflectance = [0.8, 0.6, 0.4]
[[shapes]]
type = "quad"
origin = [-10.0, -10.0, 0.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
material = "wall"
[[shapes]]
type = "sphere"
center = [0.3, 0.0, 0.5]
radius = 0.5
material = "wall"
[[lights]]
type = "point"
position = [0.0, 1.0, 1.5]
intensity = [4.0, 4.0, 4.0]
"#;

fn load(name: &str) -> Yaml {
    let path = root().join("deploy").join("kubernetes").join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut docs = YamlLoader::load_from_str(&text).unwrap();
    assert_eq!(docs.len(), 1, "{name}: one document");
    docs.remove(0)
}

fn str_list(y: &Yaml) -> Vec<String> {
    y.as_vec()
        .unwrap_or_else(|| panic!("expected a list, got {y:?}"))
        .iter()
        .map(|v| match v {
            Yaml::String(s) => s.clone(),
            Yaml::Integer(i) => i.to_string(),
            other => panic!("expected a string, got {other:?}"),
        })
        .collect()
}

/// A container's command line: `command` then `args`.
fn command_line(container: &Yaml) -> Vec<String> {
    let mut line = str_list(&container["command"]);
    if !container["args"].is_badvalue() {
        line.extend(str_list(&container["args"]));
    }
    line
}

/// The pod's containers: init containers first, then the main ones.
fn containers(job: &Yaml) -> Vec<&Yaml> {
    let pod = &job["spec"]["template"]["spec"];
    let mut all: Vec<&Yaml> = Vec::new();
    for key in ["initContainers", "containers"] {
        if let Some(list) = pod[key].as_vec() {
            all.extend(list);
        }
    }
    all
}

/// The claim the pod's volume `shared` uses and where every container mounts it (one path).
fn shared_mount(job: &Yaml) -> (String, String) {
    let pod = &job["spec"]["template"]["spec"];
    let volumes = pod["volumes"].as_vec().unwrap();
    assert_eq!(volumes.len(), 1);
    let name = volumes[0]["name"].as_str().unwrap();
    let claim = volumes[0]["persistentVolumeClaim"]["claimName"]
        .as_str()
        .unwrap();
    let mut mount = None;
    for c in containers(job) {
        let mounts = c["volumeMounts"].as_vec().unwrap();
        assert_eq!(mounts.len(), 1);
        assert_eq!(mounts[0]["name"].as_str(), Some(name));
        let path = mounts[0]["mountPath"].as_str().unwrap().to_string();
        assert!(mount.get_or_insert(path.clone()) == &path, "one mount path");
    }
    (claim.to_string(), mount.unwrap())
}

/// Runs a container's command line as its pod would: `$(JOB_COMPLETION_INDEX)` expanded, the
/// mount path mapped to `local`, `obscura` the binary under test.
fn run_as_pod(line: &[String], index: Option<u32>, mount: &str, local: &Path) {
    let expanded: Vec<String> = line
        .iter()
        .map(|a| {
            let a = match index {
                Some(i) => a.replace("$(JOB_COMPLETION_INDEX)", &i.to_string()),
                None => a.clone(),
            };
            assert!(!a.contains("$("), "an unexpanded variable in {a}");
            if a.starts_with('/') {
                assert!(
                    a.starts_with(&format!("{mount}/")),
                    "{a} is not on the shared volume {mount}"
                );
                a.replacen(mount, local.to_str().unwrap(), 1)
            } else {
                a
            }
        })
        .collect();
    let mut cmd = if expanded[0] == "obscura" {
        obscura()
    } else {
        std::process::Command::new(&expanded[0])
    };
    let out = cmd.args(&expanded[1..]).output().unwrap();
    assert!(
        out.status.success(),
        "{expanded:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_kubernetes_manifests_wire_up_and_merge_exactly() {
    let pvc = load("shared-volume.yaml");
    let slices = load("render-slices.yaml");
    let merge = load("merge.yaml");
    assert_eq!(pvc["kind"].as_str(), Some("PersistentVolumeClaim"));
    assert!(str_list(&pvc["spec"]["accessModes"]).contains(&"ReadWriteMany".to_string()));
    let claim_name = pvc["metadata"]["name"].as_str().unwrap();

    // The Indexed Job: N completions, retries, N in the --slice flag.
    assert_eq!(slices["kind"].as_str(), Some("Job"));
    let spec = &slices["spec"];
    assert_eq!(spec["completionMode"].as_str(), Some("Indexed"));
    let n = spec["completions"].as_i64().unwrap();
    assert!(n >= 1);
    let parallelism = spec["parallelism"].as_i64().unwrap();
    assert!((1..=n).contains(&parallelism));
    assert!(spec["backoffLimit"].as_i64().unwrap() >= 1, "retries");
    let render = containers(&slices)
        .into_iter()
        .find(|c| command_line(c).get(1).map(String::as_str) == Some("render"))
        .expect("a render container");
    let line = command_line(render);
    let flag = |line: &[String], name: &str| {
        let at = line
            .iter()
            .position(|a| a == name)
            .unwrap_or_else(|| panic!("{name} in {line:?}"));
        line[at + 1].clone()
    };
    assert_eq!(
        flag(&line, "--slice"),
        format!("$(JOB_COMPLETION_INDEX)/{n}")
    );
    let part_pattern = flag(&line, "-o");
    assert!(part_pattern.contains("$(JOB_COMPLETION_INDEX)"));

    // The merge Job: --slices N and exactly the N parts the render pods write.
    let merge_line = command_line(
        containers(&merge)
            .into_iter()
            .find(|c| command_line(c).get(1).map(String::as_str) == Some("merge"))
            .expect("a merge container"),
    );
    assert_eq!(flag(&merge_line, "--slices"), n.to_string());
    let parts: Vec<String> = (0..n)
        .map(|i| part_pattern.replace("$(JOB_COMPLETION_INDEX)", &i.to_string()))
        .collect();
    let given: Vec<String> = merge_line
        .iter()
        .filter(|a| a.ends_with(".part"))
        .cloned()
        .collect();
    assert_eq!(given, parts, "the merge reads what the pods write");

    // One claim, one mount path for both Jobs.
    let (render_claim, mount) = shared_mount(&slices);
    let (merge_claim, merge_mount) = shared_mount(&merge);
    assert_eq!(
        (render_claim.as_str(), merge_claim.as_str()),
        (claim_name, claim_name)
    );
    assert_eq!(mount, merge_mount);

    // Run them: the scene at the manifests' path, each index's pod, then the merge's.
    let local = scratch("kubernetes");
    let scene = PathBuf::from(flag(&line, "render"));
    let scene_local = local.join(scene.strip_prefix(&mount).unwrap());
    std::fs::create_dir_all(scene_local.parent().unwrap()).unwrap();
    std::fs::write(&scene_local, SCENE).unwrap();
    for i in 0..n as u32 {
        for c in containers(&slices) {
            run_as_pod(&command_line(c), Some(i), &mount, &local);
        }
    }
    for c in containers(&merge) {
        run_as_pod(&command_line(c), None, &mount, &local);
    }
    let merged =
        PathBuf::from(flag(&merge_line, "-o").replacen(&mount, local.to_str().unwrap(), 1));
    let whole = local.join("whole.exr");
    let out = obscura()
        .args([
            "render",
            scene_local.to_str().unwrap(),
            "--threads",
            "1",
            "-o",
        ])
        .arg(&whole)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(std::fs::read(&merged).unwrap() == std::fs::read(&whole).unwrap());
}
