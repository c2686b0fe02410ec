//! Throwaway probe (issue 43, deliverable 2): reference arch at the DEM's peak: Winkler offsets + P-Δ in the LA.
use voussoir::analysis::limit::{LimitOptions, LimitProblem, LiveLoad};
use voussoir::analysis::HingeSide;
use voussoir::block::{Block, BlockId, Dof, Fixity, RigidBlock};
use voussoir::build::arch::{Arch, ArchSpec};
use voussoir::law::{CoulombSlip, MaterialId};
use voussoir::math::Vector;
use voussoir::model::Model;
use voussoir_arch::scenarios::arch_static::{build, run, ServoLoading, StaticCase};

fn main() -> voussoir::error::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let kn: f64 = args.get(1).map_or(4e9, |s| s.parse().unwrap());
    let phi: f64 = args.get(2).map_or(40.0, |s| s.parse().unwrap());
    let maxd: f64 = args.get(3).map_or(4e-3, |s| s.parse().unwrap());
    let inc: f64 = args.get(4).map_or(2e-5, |s| s.parse().unwrap());
    let thr: f64 = args.get(5).map_or(1e-4, |s| s.parse().unwrap());
    let case = StaticCase {
        label: "probe".into(),
        friction_deg: phi,
        kn,
        ks: 0.4 * kn,
        max_displacement: maxd,
        servo: Some(ServoLoading { increment: inc, max_unbalanced_ratio: thr }),
        ..StaticCase::baseline()
    };
    let spec = ArchSpec::reference(case.width);
    let arch = Arch::new(&spec)?;
    let joints = arch.joint_refs();
    let plate = BlockId(15);
    let loaded = BlockId(5);
    let mut best = (0.0, String::new());
    let r = run(&case, Some(inc), |m| {
        let load = m.contact_between(plate, loaded).map(|c| c.resultant().y).unwrap_or(0.0);
        if load > best.0 {
            best = (load, m.to_checkpoint_string()?);
        }
        Ok(())
    })?;
    println!("kn {kn:e} phi {phi}: DEM peak {:.1} N at {:.3} mm ({}), LA before loading {:.1} N ({})", r.peak_load, r.displacement_at_peak * 1e3, r.mechanism_at_peak.describe(), r.limit.load, r.limit.mechanism.describe());
    let m: Model = Model::from_checkpoint_str(&best.1)?;
    let t = spec.thickness;
    let d = spec.width;
    let rot = |k: usize| -> f64 {
        let b = m.block(BlockId(k as u32)).unwrap();
        (b.state().pose.rotation * b.initial_pose().rotation.inverse()).to_scaled_axis().z
    };
    let n = spec.voussoirs;
    let mut winkler = vec![0.0f64; n + 1];
    for j in 0..=n {
        let c = m.contact_between(BlockId(j as u32), BlockId(j as u32 + 1)).unwrap();
        let nf = c.normal_force();
        let Some(pa) = c.application_point() else { println!("  joint {j}: open"); continue };
        let jr = arch.joints[j];
        let lb = m.block(BlockId(j as u32))?;
        let (i, e) = (jr.intrados + lb.displacement_of(jr.intrados), jr.extrados + lb.displacement_of(jr.extrados));
        let s = (pa - i).dot((e - i).normalize());
        let ph = rot(j + 1) - rot(j);
        let cw = (2.0 * nf / (kn * d * ph.abs())).sqrt();
        winkler[j] = cw / 3.0;
        let hinge = s < t / 3.0 || s > 2.0 * t / 3.0;
        println!("  joint {j}: N {nf:.1} N, resultant {:.2} mm from intrados, edge distance {:.3} mm, rotation {ph:.3e}, Winkler c/3 {:.3} mm{}", s * 1e3, s.min(t - s) * 1e3, cw / 3.0 * 1e3, if hinge { " HINGE" } else { "" });
    }
    // The plate's initial block.
    let sm = build(&case)?;
    let plate0 = sm.model.blocks()[plate.index()].clone();
    let la = |deformed: bool, set: &Vec<(f64, f64)>| -> voussoir::error::Result<(f64, String, Vec<(usize, bool)>)> {
        let mut f: Model = Model::new(*m.parameters())?;
        let law = CoulombSlip::dry(kn, 0.4 * kn, phi)?;
        for (a, b) in [(MaterialId(0), MaterialId(0)), (MaterialId(0), MaterialId(1)), (MaterialId(1), MaterialId(1))] {
            f.set_joint_law(a, b, law)?;
        }
        for k in 0..=n + 2 {
            let mut blk: RigidBlock = if k == n + 2 { plate0.clone() } else { arch.blocks[k].clone() };
            if (1..=n).contains(&k) {
                let (i0, e0) = spec.joint_points(k - 1);
                let (i1, e1) = spec.joint_points(k);
                let mut outline = vec![];
                let mut corner = |p: Vector, along_joint: Vector, along_face: Vector, e: f64| {
                    if e > 0.0 { outline.push(p + along_joint * e); outline.push(p + along_face * (0.3 * e)); } else { outline.push(p); }
                };
                let r0 = (e0 - i0).normalize();
                let r1 = (e1 - i1).normalize();
                let (ei0, ee0) = if k == 1 { set[0] } else { (0.0, 0.0) };
                let (ei1, ee1) = set[k];
                corner(i0, r0, (i1 - i0).normalize(), ei0);
                corner(e0, -r0, (e1 - e0).normalize(), ee0);
                corner(i1, r1, (i0 - i1).normalize(), ei1);
                corner(e1, -r1, (e0 - e1).normalize(), ee1);
                let pts: Vec<Vector> = outline.iter().flat_map(|p| [Vector::new(p.x, p.y, 0.0), Vector::new(p.x, p.y, d)]).collect();
                blk = RigidBlock::from_vertices(arch.blocks[k].name(), &pts, spec.density)?.with_material(MaterialId(0));
            }
            if deformed {
                let db = m.block(BlockId(k as u32))?;
                blk = blk.transformed(db.state().pose * db.initial_pose().inverse());
            }
            f.add_block(blk)?;
        }
        f.step()?;
        let mut p = LimitProblem::from_model(&f)?;
        p.set_fixity(plate, Fixity { translation: [Dof::Free, Dof::Free, Dof::Fixed], rotation: [Dof::Fixed, Dof::Fixed, Dof::Free] })?;
        let pb = &f.blocks()[plate.index()];
        let r = p.solve(&[LiveLoad { block: plate, point: pb.state().pose.translation, force: -Vector::Y }], &LimitOptions { check_dead_load: false, ..LimitOptions::default() })?;
        let w = pb.mass_properties().mass * 9.81;
        let (_, mech) = r.classify(&f, &joints, 1e-3);
        let hs = mech.hinges.iter().map(|h| (h.joint, h.side == HingeSide::Intrados)).collect();
        Ok((r.multiplier + w, mech.describe(), hs))
    };
    let none = vec![(0.0, 0.0); n + 1];
    for deformed in [false, true] {
        let (l, ms, mut hs) = la(deformed, &none)?;
        if hs.is_empty() { hs = vec![(0, true), (5, false), (9, true), (13, false)]; }
        println!("  LA {} : {l:.1} N ({ms})", if deformed { "deformed" } else { "undeformed" });
        let mut set = none.clone();
        for it in 0..6 {
            let mut changed = false;
            for &(j, intra) in &hs {
                let o = if intra { &mut set[j].0 } else { &mut set[j].1 };
                if *o == 0.0 { *o = winkler[j].min(0.45 * t).max(1e-6); changed = true; }
            }
            if !changed { break; }
            let (l, ms, h) = la(deformed, &set)?;
            println!("  LA {} shrunk (it {it}): {l:.1} N ({ms}); shrink {:?}", if deformed { "deformed" } else { "undeformed" },
                set.iter().enumerate().filter(|x| x.1.0 > 0.0 || x.1.1 > 0.0).map(|(j, o)| format!("{j}:{:.1}/{:.1}mm", o.0 * 1e3, o.1 * 1e3)).collect::<Vec<_>>());
            hs = h;
        }
    }
    println!("  DEM peak {:.1} N", best.0);
    Ok(())
}
