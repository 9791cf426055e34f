//! A command's outputs put in place together (`io::output::OutputGroup`): all of them or none,
//! and a file replaced before a later rename failed is restored. One test in its own process:
//! the group is process-wide.
use std::io::Write;

use imu_io::output::{OutputGroup, write_atomically};

#[test]
fn a_group_puts_all_its_outputs_in_place_or_none_and_restores_what_it_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let names = || {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    };
    std::fs::write(dir.join("a.txt"), "old a").unwrap();

    // Committed: nothing is in place until the group commits.
    let group = OutputGroup::begin();
    write_atomically(&dir.join("a.txt"), |w| w.write_all(b"new a")).unwrap();
    write_atomically(&dir.join("b.txt"), |w| w.write_all(b"new b")).unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "old a");
    assert!(!dir.join("b.txt").exists());
    group.commit().unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "new a");
    assert_eq!(std::fs::read_to_string(dir.join("b.txt")).unwrap(), "new b");
    assert_eq!(names(), ["a.txt", "b.txt"]);

    // Dropped (an error in the command): none of them.
    let group = OutputGroup::begin();
    write_atomically(&dir.join("a.txt"), |w| w.write_all(b"newer a")).unwrap();
    write_atomically(&dir.join("c.txt"), |w| w.write_all(b"c")).unwrap();
    drop(group);
    assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "new a");
    assert_eq!(names(), ["a.txt", "b.txt"]);

    // A rename that fails (its place became a folder with a file in it meanwhile): the outputs
    // already renamed are taken back, the files they replaced restored, no temporary is left.
    let group = OutputGroup::begin();
    write_atomically(&dir.join("a.txt"), |w| w.write_all(b"newest a")).unwrap();
    write_atomically(&dir.join("new.txt"), |w| w.write_all(b"new")).unwrap();
    write_atomically(&dir.join("d"), |w| w.write_all(b"d")).unwrap();
    std::fs::create_dir(dir.join("d")).unwrap();
    std::fs::write(dir.join("d").join("inside"), "x").unwrap();
    let err = group.commit().expect_err("d is a folder now");
    assert!(err.to_string().contains('d'), "{err}");
    assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "new a");
    assert_eq!(names(), ["a.txt", "b.txt", "d"]);

    // A group begun inside another joins it: the outer one commits.
    let outer = OutputGroup::begin();
    let inner = OutputGroup::begin();
    write_atomically(&dir.join("e.txt"), |w| w.write_all(b"e")).unwrap();
    inner.commit().unwrap();
    assert!(!dir.join("e.txt").exists());
    outer.commit().unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("e.txt")).unwrap(), "e");
}
