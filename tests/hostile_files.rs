//! Issue 33, files: what a save leaves on disk when two threads save to one path, when the name
//! is long or a symbolic link, and that a model with a base motion that saves also loads.

use crate::common;

use std::path::PathBuf;

use voussoir::loading::{BaseMotion, MotionKind, TimeHistory};
use voussoir::prelude::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voussoir-hostile-files-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

fn stepped_model(steps: u64) -> Model {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    model.add_block(common::fixed_slab("base")).expect("slab");
    model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    model.run_steps(steps).expect("run");
    model
}

/// Two threads saving checkpoints of two different models to one path, 200 rounds each: no
/// save fails, and after every round the file loads as one of the two models (never a torn
/// file, never a fragment). On the old writer (one temporary name per process) saves failed
/// with "No such file or directory" and files were torn.
#[test]
fn two_threads_saving_to_one_path_never_tear_the_file() {
    let dir = scratch("threads");
    let path = dir.join("run.checkpoint.json");
    let models = [stepped_model(3), stepped_model(40)];
    let texts: Vec<String> = models.iter().map(|m| m.to_checkpoint_string().expect("text")).collect();
    assert_ne!(texts[0], texts[1]);
    let barrier = std::sync::Barrier::new(2);
    for round in 0..200 {
        std::thread::scope(|s| {
            for model in &models {
                let (barrier, path, texts) = (&barrier, &path, &texts);
                s.spawn(move || {
                    barrier.wait();
                    model
                        .save_checkpoint(path)
                        .unwrap_or_else(|e| panic!("round {round}: save failed: {e}"));
                    // What this Ok save left is a whole file (this thread's or the other's).
                    let text = std::fs::read_to_string(path).expect("read");
                    assert!(
                        texts.contains(&text),
                        "round {round}: the file after an Ok save is neither model's ({} bytes)",
                        text.len()
                    );
                });
            }
        });
        Model::<CoulombSlip>::load_checkpoint(&path).expect("the file loads");
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(left.len(), 1, "no temporary file left: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Names of 245 to 255 bytes (the most a file system takes) save: the temporary name stays
/// within 255 bytes. The old `.<name>.<pid>.tmp` passed 255 bytes and the save failed.
#[test]
fn long_names_save() {
    let dir = scratch("long");
    let model = stepped_model(2);
    for len in [245, 250, 255] {
        let name = format!("{}.json", "n".repeat(len - 5));
        assert_eq!(name.len(), len);
        let path = dir.join(&name);
        model
            .save_checkpoint(&path)
            .unwrap_or_else(|e| panic!("{len} bytes: {e}"));
        Model::<CoulombSlip>::load_checkpoint(&path).expect("loads");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Saving through a symbolic link writes the link's target and keeps the link (the old writer
/// replaced the link by a file).
#[cfg(unix)]
#[test]
fn saving_through_a_symlink_writes_its_target() {
    let dir = scratch("symlink");
    let real = dir.join("real").join("state.json");
    std::fs::create_dir_all(real.parent().expect("parent")).expect("folder");
    std::fs::write(&real, "old").expect("target");
    let link = dir.join("link.json");
    std::os::unix::fs::symlink("real/state.json", &link).expect("link");
    stepped_model(2).save_checkpoint(&link).expect("save");
    let meta = std::fs::symlink_metadata(&link).expect("link metadata");
    assert!(meta.file_type().is_symlink(), "the link is still a link");
    Model::<CoulombSlip>::load_checkpoint(&real).expect("the target holds the checkpoint");
    // A cycle of links is an error naming the path, not a hang.
    let a = dir.join("a.json");
    std::os::unix::fs::symlink("b.json", &a).expect("a");
    std::os::unix::fs::symlink("a.json", dir.join("b.json")).expect("b");
    let e = stepped_model(1).save_checkpoint(&a).unwrap_err();
    assert!(e.to_string().contains("symbolic links"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A target that is not a regular file is refused and left as it is: a folder, and a link to a
/// device (as root, renaming over the link's target would have replaced `/dev/null` by a file).
#[cfg(unix)]
#[test]
fn targets_that_are_not_regular_files_are_refused() {
    let dir = scratch("devices");
    let folder = dir.join("a folder.json");
    std::fs::create_dir_all(&folder).expect("folder");
    let e = stepped_model(1).save_checkpoint(&folder).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
    assert!(folder.is_dir());
    let link = dir.join("null.json");
    std::os::unix::fs::symlink("/dev/null", &link).expect("link");
    let e = stepped_model(1).save_checkpoint(&link).unwrap_err();
    assert!(
        e.to_string().contains("/dev/null") && e.to_string().contains("not a regular file"),
        "{e}"
    );
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .expect("null")
        .file_type()
        .is_char_device());
    let left: Vec<_> = std::fs::read_dir(&dir).expect("list").collect();
    assert_eq!(left.len(), 2, "nothing else written");
    let _ = std::fs::remove_dir_all(&dir);
}

fn table_with_motion() -> (Model, BlockId) {
    let mut model = common::model(CoulombSlip::dry(1e9, 4e8, 30.0).expect("law"));
    let table = model.add_block(common::fixed_slab("table")).expect("slab");
    model.add_block(common::cube("cube", Vector::ZERO)).expect("cube");
    let shake = TimeHistory::sine(1.0, 2.0, 1.0, 50).expect("history");
    model
        .set_base_motion(
            table,
            Some(BaseMotion::new(MotionKind::Acceleration, [Some(shake), None, None]).expect("motion")),
        )
        .expect("motion set");
    model.run_steps(5).expect("run");
    (model, table)
}

/// Freeing a translation a base motion drives is refused, naming the block, the axis and the
/// motion; the model still saves and loads. (It used to return Ok, and a checkpoint saved
/// before the next step did not load.)
#[test]
fn freeing_a_driven_axis_is_refused_and_what_saves_loads() {
    let (mut model, table) = table_with_motion();
    let e = model.set_fixity(table, Fixity::FREE).unwrap_err();
    assert!(
        matches!(e, Error::DrivenAxisFreed { block, axis: "x", .. } if block == table),
        "{e:?}"
    );
    let message = e.to_string();
    assert!(message.contains("Acceleration on x"), "{message}");
    let text = model.to_checkpoint_string().expect("save");
    Model::<CoulombSlip>::from_checkpoint_str(&text).expect("what saves loads");
    // Fixing the driven axis (and freeing another) is accepted.
    let mut fixity = Fixity::FIXED;
    fixity.translation[1] = Dof::Free;
    model.set_fixity(table, fixity).expect("y is not driven");
    let text = model.to_checkpoint_string().expect("save");
    Model::<CoulombSlip>::from_checkpoint_str(&text).expect("loads");
}

/// Removing a base motion stops the block (its driven axes become fixed) instead of leaving it
/// moving at its last velocity for ever; freeing the axis afterwards is accepted.
#[test]
fn removing_a_base_motion_stops_the_block() {
    let (mut model, table) = table_with_motion();
    model.run_steps(200).expect("run");
    assert!(model.block(table).expect("table").state().velocity.x.abs() > 0.0);
    model.set_base_motion(table, None).expect("removed");
    assert_eq!(model.block(table).expect("table").fixity().translation[0], Dof::Fixed);
    let x = model.block(table).expect("table").state().pose.translation.x;
    model.run_steps(100).expect("run");
    let after = model.block(table).expect("table").state().pose.translation.x;
    assert_eq!(after, x, "the table stays where the motion left it");
    model.set_fixity(table, Fixity::FREE).expect("no motion now");
}

/// A series whose folder is deleted mid-run: the next frame is an error naming the missing
/// file (it used to recreate the folder and list frames that no longer exist).
#[test]
fn a_series_whose_folder_is_deleted_mid_run_says_so() {
    let dir = scratch("series-deleted");
    let mut model = stepped_model(1);
    let mut series = voussoir::io::vtk::Series::try_new(dir.join("out"), "run").expect("series");
    series.write_frame(&model).expect("frame 0");
    model.run_steps(2).expect("run");
    series.write_frame(&model).expect("frame 1");
    std::fs::remove_dir_all(dir.join("out")).expect("deleted");
    let e = series.write_frame(&model).unwrap_err().to_string();
    assert!(e.contains("run_blocks_00000.vtu") && e.contains("gone"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two series writing one name into one folder: the second is refused at its first frame,
/// naming the lock file (they used to overwrite each other's frames). Once the first is
/// dropped its lock is gone and a new series writes; a lock left by a process that ended is
/// taken over.
#[test]
fn two_series_of_one_name_in_one_folder_are_refused() {
    use voussoir::io::vtk::Series;
    let dir = scratch("series-lock");
    let model = stepped_model(1);
    let mut first = Series::try_new(&dir, "wall").expect("series");
    first.write_frame(&model).expect("first");
    let mut second = Series::try_new(&dir, "wall").expect("series");
    let e = second.write_frame(&model).unwrap_err().to_string();
    assert!(e.contains(".wall.lock") && e.contains("another series"), "{e}");
    let mut clone = first.clone();
    assert!(clone.write_frame(&model).is_err(), "a clone holds no lock");
    // Another name in the same folder is fine.
    Series::try_new(&dir, "arch")
        .expect("series")
        .write_frame(&model)
        .expect("another name");
    drop(first);
    assert!(!dir.join(".wall.lock").exists(), "the lock is removed with its series");
    second.write_frame(&model).expect("the folder is free now");
    drop(second);
    // A lock of a process that no longer runs (pid beyond Linux's pid_max).
    std::fs::write(dir.join(".wall.lock"), "4294967295 0\n").expect("stale lock");
    let mut third = Series::try_new(&dir, "wall").expect("series");
    if cfg!(target_os = "linux") {
        third.write_frame(&model).expect("a stale lock is taken over");
    }
    drop(third);
    let _ = std::fs::remove_dir_all(&dir);
}
