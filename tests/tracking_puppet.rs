//! The tracking puppet and its light mesh, checked against the retargeting of the CMU clips:
//! exact reproduction of retargeted poses, joint limits that hold every retargeted frame,
//! pre-positioning from noisy joints, body proportions, and the clustered mesh.

use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Instant;

use emilion::body::{Animation, Mannequin, Motion, Pose, RetargetOptions};
use emilion::geometry::{SplitMix64, Vec3};
use emilion::tracking::joints::{JointSet, JOINT_COUNT, TRACKING_JOINTS};
use emilion::tracking::puppet::{PartGroup, Proportions, Puppet, PARAM_COUNT};
use emilion::tracking::puppet_mesh::{TrackingMesh, DEFAULT_CELL};

const CLIPS: [&str; 8] = [
    "002_01", "002_02", "002_03", "002_05", "005_01", "006_01", "007_01", "007_02",
];

fn data() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"))
}

fn mannequin() -> &'static Mannequin {
    static M: OnceLock<Mannequin> = OnceLock::new();
    M.get_or_init(|| Mannequin::load_makehuman(&data().join("bodies/makehuman")).unwrap())
}

fn puppet() -> &'static Puppet {
    static P: OnceLock<Puppet> = OnceLock::new();
    P.get_or_init(|| Puppet::new(mannequin()).unwrap())
}

fn animation(name: &str) -> Animation {
    let path = data().join("motion/cmu_bvh").join(format!("{name}.bvh"));
    let motion = Motion::load_bvh(&path).unwrap();
    Animation::new(mannequin().clone(), motion, RetargetOptions::default()).unwrap()
}

fn frames(a: &Animation) -> usize {
    a.motion().frame_count()
}

#[test]
fn reproduces_retargeted_poses() {
    let (m, p) = (mannequin(), puppet());
    let js = JointSet::new(m).unwrap();
    let bones = m.skeleton().bones();
    let mut pose = m.rest_pose();
    let (mut worst_joint, mut worst_bone, mut count) = (0.0f64, 0.0f64, 0);
    for clip in ["002_01", "002_03", "002_05"] {
        let a = animation(clip);
        for k in (0..frames(&a)).step_by(10) {
            let truth = a.frame_pose(k);
            let params = p.params_from_pose(truth);
            assert_eq!(params.len(), PARAM_COUNT);
            p.pose_into(&params, &mut pose);
            let (ja, jb) = (js.positions(truth), p.joints(&pose));
            for j in 0..JOINT_COUNT {
                worst_joint = worst_joint.max((ja[j] - jb[j]).norm());
            }
            for (b, bone) in bones.iter().enumerate() {
                let d = (truth.apply(b, bone.head) - pose.apply(b, bone.head)).norm();
                let d2 = (truth.apply(b, bone.tail) - pose.apply(b, bone.tail)).norm();
                worst_bone = worst_bone.max(d).max(d2);
            }
            count += 1;
        }
    }
    eprintln!("{count} frames: worst joint {worst_joint:.2e} m, worst bone end {worst_bone:.2e} m");
    assert!(worst_joint < 1e-6, "joint differs by {worst_joint} m");
    assert!(worst_bone < 1e-6, "bone end differs by {worst_bone} m");
}

#[test]
fn retargeted_frames_are_within_limits() {
    let p = puppet();
    let info = p.params();
    let mut lo = vec![f64::INFINITY; PARAM_COUNT];
    let mut hi = vec![f64::NEG_INFINITY; PARAM_COUNT];
    let mut worst = (f64::INFINITY, String::new());
    let mut total = 0;
    for clip in CLIPS {
        let a = animation(clip);
        for k in 0..frames(&a) {
            let params = p.params_from_pose(a.frame_pose(k));
            for (i, &x) in params.iter().enumerate() {
                lo[i] = lo[i].min(x);
                hi[i] = hi[i].max(x);
                let margin = (x - info[i].lo).min(info[i].hi - x);
                if margin < worst.0 {
                    worst = (
                        margin,
                        format!(
                            "{} = {:.1}° in {clip} frame {k}",
                            info[i].name,
                            x.to_degrees()
                        ),
                    );
                }
            }
            total += 1;
        }
    }
    for i in 6..PARAM_COUNT {
        eprintln!(
            "{:22} data [{:7.1}, {:7.1}]°  limits [{:7.1}, {:7.1}]°",
            info[i].name,
            lo[i].to_degrees(),
            hi[i].to_degrees(),
            info[i].lo.to_degrees(),
            info[i].hi.to_degrees()
        );
    }
    eprintln!(
        "{total} frames, worst margin {:.2}° ({})",
        worst.0.to_degrees(),
        worst.1
    );
    assert!(
        worst.0 >= 0.0,
        "outside the limits by {:.3}°: {}",
        -worst.0.to_degrees(),
        worst.1
    );
}

#[test]
fn parameters_are_described() {
    let p = puppet();
    assert_eq!(p.param_count(), PARAM_COUNT);
    assert_eq!(p.params().len(), PARAM_COUNT);
    assert!(p
        .params()
        .iter()
        .all(|i| i.lo < 0.0 && i.hi > 0.0 && !i.name.is_empty()));
    assert_eq!(p.params()[6].group, PartGroup::Torso);
    let rest = p.rest_params();
    assert!(rest.iter().all(|&x| x == 0.0));
    let mut pose = mannequin().rest_pose();
    p.pose_into(&rest, &mut pose);
    let js = JointSet::new(mannequin()).unwrap();
    let rest_joints = js.positions(&mannequin().rest_pose());
    let j = p.joints(&pose);
    for k in 0..JOINT_COUNT {
        assert!(
            (j[k] - rest_joints[k]).norm() < 1e-12,
            "{}",
            TRACKING_JOINTS[k].name
        );
    }
    // bad input does not panic: short, non-finite parameters and a short pose
    let mut bad = vec![f64::NAN; 5];
    p.pose_into(&bad, &mut pose);
    assert!(p
        .joints(&pose)
        .iter()
        .all(|v| v.iter().all(|x| x.is_finite())));
    p.clamp(&mut bad);
    assert!(bad.iter().all(|&x| x == 0.0));
    let short = Pose::identity(3);
    let _ = p.joints(&short);
    assert_eq!(p.params_from_pose(&short).len(), PARAM_COUNT);
    let mut wrong = Pose::identity(2);
    p.pose_into(&rest, &mut wrong);
    assert_eq!(wrong.len(), p.bone_count());

    // timing (reported, not asserted)
    let a = animation("002_01");
    let params = p.params_from_pose(a.frame_pose(40));
    let n = 20_000;
    let t = Instant::now();
    for _ in 0..n {
        p.pose_into(std::hint::black_box(&params), &mut pose);
    }
    eprintln!(
        "pose_into: {:.2} µs for {} bones",
        t.elapsed().as_secs_f64() * 1e6 / n as f64,
        p.bone_count()
    );
}

#[test]
fn parameters_round_trip_on_proportioned_puppets() {
    let base = puppet();
    let mut rng = SplitMix64::new(11);
    let q = base
        .with_proportions(&Proportions {
            torso: 1.1,
            thigh: 0.9,
            upper_arm: 1.05,
            girth: 1.25,
            ..Proportions::default()
        })
        .unwrap();
    for p in [base, &q] {
        let mut pose = mannequin().rest_pose();
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            // random within the limits; rotation vectors shorter than π (their log is unique)
            let mut params: Vec<f64> = p.params().iter().map(|i| rng.range(i.lo, i.hi)).collect();
            for v in params[3..].chunks_mut(3) {
                let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if norm > 3.0 {
                    v.iter_mut().for_each(|x| *x *= 3.0 / norm);
                }
            }
            p.pose_into(&params, &mut pose);
            let back = p.params_from_pose(&pose);
            for (a, b) in params.iter().zip(&back) {
                worst = worst.max((a - b).abs());
            }
        }
        assert!(worst < 1e-9, "round trip differs by {worst}");
    }
    // girth leaves limb segment lengths alone
    let (mut p0, mut p1) = (mannequin().rest_pose(), mannequin().rest_pose());
    base.pose_into(&base.rest_params(), &mut p0);
    q.pose_into(&q.rest_params(), &mut p1);
    let (j0, j1) = (base.joints(&p0), q.joints(&p1));
    for (a, b, s) in [(5, 6, 1.0), (11, 12, 1.0), (10, 11, 0.9), (4, 5, 1.05)] {
        let (l0, l1) = ((j0[a] - j0[b]).norm(), (j1[a] - j1[b]).norm());
        assert!(
            (l1 - s * l0).abs() < 1e-9,
            "{} {l1} vs {l0}",
            TRACKING_JOINTS[b].name
        );
    }
}

#[test]
fn fits_noisy_joints_from_rest() {
    let p = puppet();
    let mut rng = SplitMix64::new(2024);
    let mut pose = mannequin().rest_pose();
    let sigma = 0.02 / 3f64.sqrt(); // 2 cm RMS noise per joint
    let mut worst: f64 = 0.0;
    let mut cases = Vec::new();
    for clip in CLIPS {
        let a = animation(clip);
        for k in [frames(&a) / 5, frames(&a) / 2, 4 * frames(&a) / 5] {
            cases.push((clip, k, p.joints(a.frame_pose(k))));
        }
    }
    for (clip, k, truth) in cases {
        let noisy: [Vec3; JOINT_COUNT] = std::array::from_fn(|j| {
            truth[j] + Vec3::new(rng.normal(), rng.normal(), rng.normal()) * sigma
        });
        let t = Instant::now();
        let fitted = p.fit_to_joints(&noisy, &p.rest_params());
        let dt = t.elapsed().as_secs_f64() * 1e3;
        let info = p.params();
        assert!(fitted
            .iter()
            .zip(info)
            .all(|(&x, i)| x >= i.lo && x <= i.hi));
        p.pose_into(&fitted, &mut pose);
        let j = p.joints(&pose);
        let rms = (truth
            .iter()
            .zip(&j)
            .map(|(a, b)| (a - b).norm_squared())
            .sum::<f64>()
            / JOINT_COUNT as f64)
            .sqrt();
        eprintln!(
            "{clip} frame {k}: joint RMS {:.2} cm ({dt:.1} ms)",
            rms * 100.0
        );
        worst = worst.max(rms);
    }
    assert!(worst < 0.03, "joint RMS {:.2} cm", worst * 100.0);
}

#[test]
fn forearm_proportion_scales_only_the_forearm() {
    let p = puppet();
    let q = p
        .with_proportions(&Proportions {
            forearm: 1.2,
            ..Proportions::default()
        })
        .unwrap();
    let a = animation("002_05");
    let punch = p.params_from_pose(a.frame_pose(120));
    let seg = |j: &[Vec3; JOINT_COUNT], a: usize, b: usize| (j[a] - j[b]).norm();
    // (joint, parent joint) of every segment
    let segments: Vec<(usize, usize)> = TRACKING_JOINTS
        .iter()
        .enumerate()
        .filter_map(|(k, t)| t.parent.map(|pa| (k, pa)))
        .collect();
    for params in [p.rest_params(), punch] {
        let (mut p0, mut p1) = (mannequin().rest_pose(), mannequin().rest_pose());
        p.pose_into(&params, &mut p0);
        q.pose_into(&params, &mut p1);
        let (j0, j1) = (p.joints(&p0), q.joints(&p1));
        for &(k, pa) in &segments {
            let (l0, l1) = (seg(&j0, k, pa), seg(&j1, k, pa));
            let name = TRACKING_JOINTS[k].name;
            let expect = if name.ends_with("wrist") {
                1.2 * l0
            } else {
                l0
            };
            assert!((l1 - expect).abs() < 1e-9, "{name}: {l1} vs {expect}");
        }
    }
    // the rest skin moved with it: the hands hang lower, the feet stay on the floor
    let low = |s: &[Vec3]| s.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
    assert!((low(q.rest_skin()) - low(p.rest_skin())).abs() < 1e-9);
    assert_eq!(q.rest_skin().len(), mannequin().rest_positions().len());
}

fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

#[test]
fn tracking_mesh_is_light_and_close_to_the_skin() {
    let (m, p) = (mannequin(), puppet());
    let mesh = TrackingMesh::build(m, p, DEFAULT_CELL);
    let n = mesh.rest.len();
    eprintln!(
        "tracking mesh: {} vertices, {} triangles",
        n,
        mesh.triangles.len()
    );
    assert!(
        (1000..=4000).contains(&mesh.triangles.len()),
        "{} triangles",
        mesh.triangles.len()
    );
    assert!(mesh.triangles.iter().flatten().all(|&v| (v as usize) < n));
    assert!(mesh.bone.len() == n && mesh.part.len() == n && mesh.source.len() == n);
    let (lo, hi) = bounds(m.rest_positions());
    let (mlo, mhi) = bounds(&mesh.rest);
    let gap = (lo - mlo).abs().max().max((hi - mhi).abs().max());
    eprintln!("bounding box gap {:.2} cm", gap * 100.0);
    assert!(gap < 0.015, "bounding box differs by {gap} m");
    // winding kept outward: positive enclosed volume
    let vol: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.rest[v as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    assert!(vol > 0.03, "volume {vol}");
    // clusters never merge across parts: each vertex's part is that of its source skin
    // vertex's dominant bone, and its rigid bone belongs to that part
    let groups = p.bone_groups();
    for v in 0..n {
        let src = mesh.source[v] as usize;
        let dominant = m
            .weights()
            .influences(src)
            .fold((0, -1.0), |a, (b, w)| if w > a.1 { (b, w) } else { a })
            .0;
        assert_eq!(mesh.part[v], groups[dominant], "vertex {v}");
        assert_eq!(mesh.part[v], groups[mesh.bone[v] as usize], "vertex {v}");
        let w: f64 = mesh.lbs_weights[v].iter().sum();
        assert!((w - 1.0).abs() < 1e-12);
    }
    // a walking pose: rigid and LBS skinning against the full skin
    let a = animation("002_01");
    let pose = a.frame_pose(60);
    let mut full = Vec::new();
    m.skin(pose, &mut full);
    let mut rigid = vec![Vec3::zeros(); n];
    let mut lbs = vec![Vec3::zeros(); n];
    mesh.skin_rigid_into(pose, &mut rigid);
    mesh.skin_lbs_into(pose, &mut lbs);
    let median = |out: &[Vec3]| {
        let mut d: Vec<f64> = (0..n)
            .map(|v| (out[v] - full[mesh.source[v] as usize]).norm())
            .collect();
        d.sort_by(f64::total_cmp);
        d[n / 2]
    };
    let (mr, ml) = (median(&rigid), median(&lbs));
    eprintln!(
        "median distance to source vertex: rigid {:.2} cm, LBS {:.2} cm",
        mr * 100.0,
        ml * 100.0
    );
    assert!(mr < 0.03 && ml < 0.03);
}
