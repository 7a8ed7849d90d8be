//! The debounced file watcher as editors exercise it: rename-over saves, bursts
//! of writes handed out as one batch after the quiet period, files outside the
//! watched set ignored.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use weft_render::normalize_path as normalize;
use weft_render::{FileWatcher, QUIET};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-watch-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn watching(files: &[&PathBuf]) -> FileWatcher {
    let mut watcher = FileWatcher::new(QUIET).expect("watcher");
    let set: BTreeSet<PathBuf> = files.iter().map(|f| normalize(f)).collect();
    watcher.watch(&set).expect("watch");
    watcher
}

#[test]
fn rename_over_is_seen_and_other_files_are_not() {
    let dir = temp_dir("rename");
    let file = dir.join("a.frag");
    std::fs::write(&file, "one").expect("write");
    let mut watcher = watching(&[&file]);
    std::fs::write(dir.join("other.txt"), "noise").expect("write other");
    assert!(watcher
        .next_batch(Duration::from_millis(300))
        .expect("batch")
        .is_empty());
    let tmp = dir.join(".a.frag.swp");
    std::fs::write(&tmp, "two").expect("write temp");
    std::fs::rename(&tmp, &file).expect("rename over");
    let batch = watcher.next_batch(Duration::from_secs(10)).expect("batch");
    assert_eq!(batch, BTreeSet::from([normalize(&file)]));
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_burst_of_writes_is_one_batch_after_the_quiet_period() {
    let dir = temp_dir("burst");
    let a = dir.join("a.ron");
    let b = dir.join("b.ron");
    std::fs::write(&a, "").expect("write a");
    std::fs::write(&b, "").expect("write b");
    let mut watcher = watching(&[&a, &b]);
    // The writer pauses QUIET / 10 between writes; on a loaded machine it can be
    // descheduled for longer than QUIET, and then the watcher rightly hands out
    // a batch mid-burst. Such a run does not exercise the debounce, so it is
    // repeated (up to five times) rather than counted.
    for attempt in 0..5 {
        let writer = {
            let (a, b) = (a.clone(), b.clone());
            std::thread::spawn(move || {
                let mut longest_gap = Duration::ZERO;
                let mut last = Instant::now();
                for i in 0..5 {
                    std::fs::write(&a, format!("part {attempt} {i}")).expect("write a");
                    std::fs::write(&b, format!("part {attempt} {i}")).expect("write b");
                    longest_gap = longest_gap.max(last.elapsed());
                    last = Instant::now();
                    std::thread::sleep(QUIET / 10);
                }
                (last, longest_gap)
            })
        };
        let batch = watcher.next_batch(Duration::from_secs(10)).expect("batch");
        let returned = Instant::now();
        let (last_write, longest_gap) = writer.join().expect("writer");
        if longest_gap >= QUIET / 2 {
            // Drain what the interrupted burst left and try again.
            while !watcher.next_batch(QUIET * 4).expect("batch").is_empty() {}
            continue;
        }
        assert_eq!(batch, BTreeSet::from([normalize(&a), normalize(&b)]));
        assert!(
            returned.duration_since(last_write) >= QUIET / 2,
            "the batch waits for the writes to stop"
        );
        assert!(watcher
            .next_batch(Duration::from_millis(200))
            .expect("batch")
            .is_empty());
        std::fs::remove_dir_all(&dir).expect("clean up");
        return;
    }
    panic!("the writer was descheduled for longer than the quiet period in all five attempts");
}

#[test]
fn polling_never_waits_and_hands_a_burst_out_once_it_is_quiet() {
    let dir = temp_dir("poll");
    let a = dir.join("a.frag");
    let b = dir.join("b.ron");
    std::fs::write(&a, "one").expect("write");
    std::fs::write(&b, "one").expect("write");
    let mut watcher = watching(&[&a, &b]);
    std::fs::write(&a, "two").expect("write a");
    std::fs::write(&b, "two").expect("write b");
    let started = Instant::now();
    let mut polls = 0;
    let batch = loop {
        let before = Instant::now();
        let batch = watcher.poll_batch().expect("poll");
        assert!(
            before.elapsed() < QUIET,
            "a poll waited {:?}",
            before.elapsed()
        );
        polls += 1;
        if !batch.is_empty() {
            break batch;
        }
        assert!(started.elapsed() < Duration::from_secs(10), "no batch");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert!(
        started.elapsed() >= QUIET,
        "handed out before the quiet period"
    );
    assert!(
        polls > 1,
        "the first poll came before the quiet period ended"
    );
    assert_eq!(batch, BTreeSet::from([normalize(&a), normalize(&b)]));
    assert!(watcher.poll_batch().expect("poll").is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}
