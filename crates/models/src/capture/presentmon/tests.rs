use super::*;

const HEAD: &str = "Application,ProcessID,SwapChainAddress,PresentMode,SyncInterval,AllowsTearing,TimeInQPC,CPUStartQPC,MsCPUBusy,MsCPUWait,MsGPULatency,MsGPUBusy,MsRenderPresentLatency,MsUntilDisplayed,MsBetweenDisplayChange\n";

fn row(start: u64, busy: f64, until: &str) -> String {
    let at = start + (busy * 10_000.0) as u64;
    format!("a.exe,1,0x1,Hardware: Legacy Flip,1,0,{at},{start},{busy},0.1,0.5,2.0,0.1,{until},NA\n")
}

#[test]
fn reads_v2_with_qpc_na_and_a_byte_order_mark() {
    let text = format!("\u{feff}{HEAD}{}{}", row(0, 10.0, "5.0"), row(101_000, 10.0, "NA"));
    let c = Capture::parse("t.csv", text.as_bytes()).unwrap();
    assert_eq!(c.columns, Columns::V2);
    assert_eq!(c.qpc_per_ms, Some(10_000.0));
    assert_eq!(c.presents.len(), 2);
    let p = &c.presents[1];
    assert!((p.cpu_start - 10.1).abs() < 1e-9 && (p.present - 20.1).abs() < 1e-9);
    assert_eq!(p.until_displayed, None);
    assert_eq!(c.presents[0].screen_time(), Some(15.0));
    assert_eq!(c.presents[0].line, 2);
}

#[test]
fn reads_each_name_of_the_cpu_start_and_a_missing_wait_as_none() {
    for (name, scale) in [
        ("CPUStartTime", 1.0),
        ("CPUStartTimeInMs", 1.0),
        ("CPUStartQPCTime", 1.0),
        ("CPUStartTimeInSeconds", 1e-3),
    ] {
        let text = format!(
            "Application,ProcessID,SwapChainAddress,PresentMode,{name},MsCPUBusy,MsCPUWait,MsUntilDisplayed\n\
             a.exe,1,0x1,Hardware: Legacy Flip,{},10,NA,5\n",
            250.0 * scale
        );
        let c = Capture::parse("t.csv", text.as_bytes()).unwrap();
        assert_eq!(c.columns, Columns::V2, "{name}");
        let p = &c.presents[0];
        assert!(
            (p.cpu_start - 250.0).abs() < 1e-9 && (p.present - 260.0).abs() < 1e-9,
            "{name}"
        );
        assert_eq!(p.cpu_wait, 0.0, "{name}: NA is no time in the present call");
    }
}

#[test]
fn errors_name_file_line_and_column() {
    let text = format!("{HEAD}{}", row(0, 10.0, "abc"));
    let e = Capture::parse("t.csv", text.as_bytes()).unwrap_err().to_string();
    assert_eq!(
        e,
        "t.csv:2: column `MsUntilDisplayed`: \"abc\" is not a number (nor NA)"
    );
    let text = format!("{HEAD}{}", row(0, 10.0, "inf"));
    let e = Capture::parse("t.csv", text.as_bytes()).unwrap_err().to_string();
    assert!(
        e.contains("t.csv:2: column `MsUntilDisplayed`: \"inf\" is not a finite number"),
        "{e}"
    );
    let e = Capture::parse("t.csv", b"Application,SwapChainAddress\na,b\n")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.csv: not a PresentMon capture"), "{e}");
    let head = HEAD.replace("MsCPUWait,", "");
    let body = "a.exe,1,0x1,Hardware: Legacy Flip,1,0,100000,0,10,0.5,2.0,0.1,5,NA\n";
    let c = Capture::parse("t.csv", format!("{head}{body}").as_bytes()).unwrap();
    assert_eq!(c.presents[0].cpu_wait, 0.0);
    assert!(c.notes.iter().any(|n| n.contains("no `MsCPUWait`")), "{:?}", c.notes);
    let head = HEAD.replace("MsCPUBusy,", "");
    let e = Capture::parse("t.csv", format!("{head}{body}").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.csv: missing column `MsCPUBusy`"), "{e}");
    let e = Capture::parse("t.csv", HEAD.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("no rows"), "{e}");
    let e = Capture::parse("t.csv", format!("{HEAD}a,b\n").as_bytes())
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "t.csv:2: column `MsCPUBusy`: the row ends after 2 field(s), before this column (the header has 15)"
    );
}

#[test]
fn select_refuses_one_frame_and_nothing_displayed_and_orders_rows_by_time() {
    let one = format!("{HEAD}{}", row(0, 10.0, "5"));
    let c = Capture::parse("t.csv", one.as_bytes()).unwrap();
    assert!(c.select(None, None).unwrap_err().to_string().contains("has one frame"));
    let back = format!("{HEAD}{}{}", row(200_000, 10.0, "5"), row(0, 10.0, "5"));
    let c = Capture::parse("t.csv", back.as_bytes()).unwrap();
    assert!(
        c.notes.iter().any(|n| n.contains("2 row(s) were out of time order")),
        "{:?}",
        c.notes
    );
    let (_, rows) = c.select(None, None).unwrap();
    assert_eq!((rows[0].line, rows[1].line), (3, 2));
    let none = format!("{HEAD}{}{}", row(0, 10.0, "NA"), row(101_000, 10.0, "NA"));
    let c = Capture::parse("t.csv", none.as_bytes()).unwrap();
    assert!(
        c.select(None, None)
            .unwrap_err()
            .to_string()
            .contains("fewer than two displayed")
    );
    let two = format!("{HEAD}{}{}", row(0, 10.0, "5"), row(101_000, 10.0, "5"));
    let c = Capture::parse("t.csv", two.as_bytes()).unwrap();
    let e = c.select(Some("b.exe"), None).unwrap_err().to_string();
    assert!(
        e.contains("no swap chain of application \"b.exe\"; the capture has: a.exe (process 1) 0x1"),
        "{e}"
    );
    assert_eq!(c.select(Some("A.EXE"), Some("0x1")).unwrap().1.len(), 2);
}

const V1: &str = "Application,ProcessID,SwapChainAddress,Runtime,SyncInterval,PresentFlags,AllowsTearing,PresentMode,Dropped,TimeInSeconds,MsBetweenPresents,MsBetweenDisplayChange,MsInPresentAPI,MsUntilRenderComplete,MsUntilDisplayed";

fn v1_row(app: &str, t: f64, dropped: &str, until: f64) -> String {
    format!("{app},7,0x9,DXGI,1,0,0,Composed: Flip,{dropped},{t},16.6,16.7,0.5,3.0,{until}\n")
}

#[test]
fn capframex_header_lines_are_metadata_and_lines_count_from_the_file_s_top() {
    let text = format!(
        "//GameName=re2.exe\n//Comment=Test run\n//GPU=NVIDIA GeForce RTX 2080 Ti\n{V1}\n{}{}{}",
        v1_row("re2.exe", 0.0, "0", 20.0),
        v1_row("re2.exe", 0.0166, "1", 0.0),
        v1_row("re2.exe", 0.0333, "0", 20.0),
    );
    let c = Capture::parse("c.csv", text.as_bytes()).unwrap();
    assert_eq!(c.columns, Columns::V1);
    assert_eq!(c.metadata[0], ("GameName".to_string(), "re2.exe".to_string()));
    assert!(c.metadata.iter().any(|(k, v)| k == "Comment" && v == "Test run"));
    assert_eq!(c.presents.len(), 3);
    assert_eq!(
        c.presents[0].line, 5,
        "line 5: after three header lines and the column header"
    );
    assert!(!c.presents[1].displayed());
    // An error names the file's own line.
    let bad = text.replace("0.0333,16.6", "0.0333,sixteen");
    let e = Capture::parse("c.csv", bad.as_bytes()).unwrap_err().to_string();
    assert!(e.starts_with("c.csv:7: column `MsBetweenPresents`"), "{e}");
}

#[test]
fn ocat_s_system_columns_on_its_first_row_are_metadata_and_short_rows_read() {
    let head = format!("{V1},Motherboard,OS,Processor,GPU,Comment");
    let first = v1_row("Metro.exe", 0.0, "0", 13.5).trim_end().to_string()
        + ",\"MSI, Z390\",Windows 10,i9-9900K,GeForce RTX 2080 Ti,Test\n";
    let text = format!(
        "{head}\n{first}{}{}warning: 12 events were lost; collected data may be unreliable.\n",
        v1_row("Metro.exe", 0.012, "0", 13.0),
        v1_row("Metro.exe", 0.024, "0", 12.0)
    );
    let c = Capture::parse("o.csv", text.as_bytes()).unwrap();
    assert_eq!(c.presents.len(), 3);
    assert!(c.metadata.iter().any(|(k, v)| k == "Motherboard" && v == "MSI, Z390"));
    assert!(c.metadata.iter().any(|(k, v)| k == "GPU" && v == "GeForce RTX 2080 Ti"));
    let notes = c.notes.join("\n");
    assert!(notes.contains("2 row(s) have fewer fields than the header"), "{notes}");
    assert!(notes.contains("1 line(s) that are not rows"), "{notes}");
    // A row with more fields than the header: the extras are ignored.
    let long = format!(
        "{V1}\n{}{}",
        v1_row("a.exe", 0.0, "0", 5.0).trim_end().to_string() + ",9,9\n",
        v1_row("a.exe", 0.02, "0", 5.0)
    );
    let c = Capture::parse("o.csv", long.as_bytes()).unwrap();
    assert!(
        c.notes.join(" ").contains("1 row(s) have more fields than the header"),
        "{:?}",
        c.notes
    );
}

#[test]
fn lower_case_names_repeated_headers_errors_in_dropped_and_impossible_values() {
    let head = "Application,ProcessID,SwapChainAddress,Runtime,SyncInterval,PresentFlags,Dropped,TimeInSeconds,msInPresentAPI,msBetweenPresents,AllowsTearing,PresentMode,msUntilRenderComplete,msUntilDisplayed,msBetweenDisplayChange";
    let row = |t: f64, dropped: &str, between_change: &str| {
        format!("g.exe,1,0x1,DXGI,0,0,{dropped},{t},0.2,8.0,0,Hardware: Independent Flip,4.0,6.0,{between_change}\n")
    };
    let text = format!(
        "{head}\n{}{head}\n{}{}",
        row(1.0, "0", "8.3"),
        row(1.008, "Error", "8.3"),
        row(1.016, "0", "1844674407370955.5")
    );
    let c = Capture::parse("l.csv", text.as_bytes()).unwrap();
    assert_eq!(c.presents.len(), 3);
    assert_eq!(c.presents[0].until_displayed, Some(6.0));
    let p = &c.presents[1];
    assert!(!p.fate_known && !p.displayed());
    assert_eq!(c.presents[2].between_display_change, None);
    let notes = c.notes.join("\n");
    assert!(notes.contains("1 repeated header row(s) skipped"), "{notes}");
    assert!(notes.contains("`Dropped` of neither 0 nor 1"), "{notes}");
    assert!(
        notes.contains("first: line 5, column `msBetweenDisplayChange`"),
        "{notes}"
    );
    // The v1 CPU start: the previous present call's end.
    assert!(
        (c.presents[1].cpu_start - 1000.2).abs() < 1e-9,
        "{}",
        c.presents[1].cpu_start
    );
}

#[test]
fn presentmon_2_s_own_names_and_its_qpc_start_without_a_present_time() {
    // 2.3.0's default: CPUStartQPC (10 MHz), FrameTime, CPUBusy, CPUWait,
    // GPULatency, GPUTime, DisplayLatency (CPU start to screen).
    let head = "Application,ProcessID,SwapChainAddress,PresentRuntime,SyncInterval,PresentFlags,AllowsTearing,PresentMode,CPUStartQPC,FrameTime,CPUBusy,CPUWait,GPULatency,GPUTime,GPUBusy,GPUWait,DisplayLatency,DisplayedTime";
    let mut text = format!("{head}\n");
    for i in 0..5u64 {
        let start = 1_000_000 + i * 166_670; // 16.667 ms apart at 10 MHz
        let shown = if i == 2 {
            "NA,NA".to_string()
        } else {
            "20.0,16.667".to_string()
        };
        text += &format!("g.exe,1,0x1,DXGI,1,0,0,Composed: Flip,{start},16.667,12.0,4.667,1.0,9.0,8.0,1.0,{shown}\n");
    }
    let c = Capture::parse("p.csv", text.as_bytes()).unwrap();
    assert_eq!(c.columns, Columns::V2);
    let rate = c.qpc_per_ms.unwrap();
    assert!((rate - 10_000.0).abs() < 1.0, "{rate}");
    let p = &c.presents[1];
    // Counted from the earliest stamp (100 ms).
    assert!((p.cpu_start - 16.667).abs() < 1e-3, "{}", p.cpu_start);
    assert!((p.present - (p.cpu_start + 12.0)).abs() < 1e-9);
    assert!(
        (p.until_displayed.unwrap() - 8.0).abs() < 1e-9,
        "DisplayLatency less CPUBusy"
    );
    assert!(
        (p.render_complete.unwrap() - -2.0).abs() < 1e-9,
        "GPU start plus time, from the present"
    );
    assert!(!c.presents[2].displayed());
    // 2.3.1's default: TimeInMs and CPUStartTimeInMs.
    let head = "Application,ProcessID,SwapChainAddress,PresentRuntime,SyncInterval,PresentFlags,AllowsTearing,PresentMode,TimeInMs,MsBetweenPresents,MsUntilDisplayed,CPUStartTimeInMs,MsCPUBusy,MsCPUWait";
    let text = format!("{head}\ng.exe,1,0x1,DXGI,1,0,0,Composed: Flip,110.5,16.6,9.0,100.0,10.5,1.0\n");
    let c = Capture::parse("p.csv", text.as_bytes()).unwrap();
    assert_eq!((c.presents[0].cpu_start, c.presents[0].present), (100.0, 110.5));
}

#[test]
fn generated_frames_are_kept_apart_and_a_restarted_clock_keeps_the_longest_recording() {
    let head = "Application,ProcessID,SwapChainAddress,PresentMode,FrameType,CPUStartTime,MsCPUBusy,MsCPUWait,MsUntilDisplayed";
    let mut text = format!("{head}\n");
    for (t, kind) in [
        (0.0, "Application"),
        (5.0, "Intel XeSS-FG"),
        (10.0, "Application"),
        (15.0, "AMD AFMF"),
        (20.0, "Unknown"),
    ] {
        text += &format!("g.exe,1,0x1,Hardware: Independent Flip,{kind},{t},4.0,1.0,3.0\n");
    }
    let c = Capture::parse("g.csv", text.as_bytes()).unwrap();
    assert_eq!((c.presents.len(), c.generated.len(), c.not_rendered()), (3, 2, 2));
    assert!(c.generated.iter().all(|g| !g.rendered()));
    // The clock goes back 50 s at line 4: two recordings, the longer read.
    let mut text = format!("{head}\n");
    for t in [50_000.0, 50_010.0, 0.0, 10.0, 20.0] {
        text += &format!("g.exe,1,0x1,Hardware: Independent Flip,Application,{t},4.0,1.0,3.0\n");
    }
    let c = Capture::parse("g.csv", text.as_bytes()).unwrap();
    assert_eq!(c.presents.iter().map(|p| p.line).collect::<Vec<_>>(), [4, 5, 6]);
    assert!(c.notes.join(" ").contains("line 4 goes back 50.0 s"), "{:?}", c.notes);
}

/// A capture of `n` frames 16.667 ms apart, QPC at 10 MHz from `base`.
fn frames_from(base: u64, n: u64) -> String {
    (0..n)
        .map(|i| {
            let start = base + i * 166_670;
            let at = start + 50_000;
            format!("a.exe,1,0x1,Hardware: Legacy Flip,1,0,{at},{start},5.0,0.1,0.5,2.0,0.1,3.0,NA\n")
        })
        .collect()
}

#[test]
fn qpc_stamps_count_from_the_earliest_near_2_pow_62_too_and_negative_ones_are_refused() {
    // As `f64` milliseconds since boot, stamps near 2^62 ticks keep only
    // about 0.1 ms (the refresh fitted 60.21 Hz instead of 59.95): they are
    // counted from the earliest stamp, exactly.
    let base = 1u64 << 62;
    let c = Capture::parse("t.csv", format!("{HEAD}{}", frames_from(base, 50)).as_bytes()).unwrap();
    assert_eq!(c.qpc_per_ms, Some(10_000.0));
    for w in c.presents.windows(2) {
        assert!(
            (w[1].present - w[0].present - 16.667).abs() < 1e-9,
            "{}",
            w[1].present - w[0].present
        );
    }
    // Any stamps count from the earliest: the same frames an hour after
    // boot read exactly as at 2^62.
    let early = Capture::parse("t.csv", format!("{HEAD}{}", frames_from(36_000_000_000, 50)).as_bytes()).unwrap();
    assert_eq!(early.presents[0].cpu_start, 0.0);
    for (a, b) in early.presents.iter().zip(&c.presents) {
        assert_eq!((a.cpu_start, a.present), (b.cpu_start, b.present));
    }
    let text = format!("{HEAD}{}", frames_from(0, 2)).replace(",0,5.0,", ",-7,5.0,");
    let e = Capture::parse("t.csv", text.as_bytes()).unwrap_err().to_string();
    assert!(
        e.contains("t.csv:2:") && e.contains("CPUStartQPC") && e.contains("negative"),
        "{e}"
    );
}

#[test]
fn a_header_naming_a_column_twice_is_refused() {
    let head = HEAD.replace("MsCPUWait", "MsCPUBusy");
    let e = Capture::parse("t.csv", format!("{head}{}", frames_from(0, 3)).as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("`MsCPUBusy` twice") && e.contains("fields 9 and 10"), "{e}");
    // Two names of one column (PresentMon 1.7's lower case beside the capitalised) too.
    let head = HEAD.replace("MsBetweenDisplayChange", "msCPUBusy");
    let e = Capture::parse("t.csv", format!("{head}{}", frames_from(0, 3)).as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("twice"), "{e}");
}

#[test]
fn rows_written_twice_are_refused_not_counted_twice() {
    let rows = frames_from(0, 4);
    let e = Capture::parse("t.csv", format!("{HEAD}{rows}{rows}").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.csv:6:") && e.contains("repeats line 2"), "{e}");
}

#[test]
fn frames_all_at_one_instant_are_refused() {
    let one: String = (0..3)
        .map(|i| {
            format!(
                "a.exe,1,0x1,Hardware: Legacy Flip,1,0,500,0,5.0,0.1,0.5,2.0,0.1,{}.0,NA\n",
                3 + i
            )
        })
        .collect();
    let c = Capture::parse("t.csv", format!("{HEAD}{one}").as_bytes()).unwrap();
    let e = c.select(None, None).unwrap_err().to_string();
    assert!(e.contains("at one instant"), "{e}");
}

#[test]
fn utf16_captures_are_read_as_their_writer_meant() {
    let text = format!("{HEAD}{}", frames_from(0, 3));
    let utf8 = Capture::parse("t.csv", text.as_bytes()).unwrap();
    let le: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(text.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    let be: Vec<u8> = text.encode_utf16().flat_map(u16::to_be_bytes).collect();
    for bytes in [le, be] {
        let c = Capture::parse("t.csv", &bytes).unwrap();
        assert_eq!(c.presents.len(), 3);
        assert_eq!(c.presents[2].present, utf8.presents[2].present);
        assert!(c.notes.iter().any(|n| n.contains("UTF-16")), "{:?}", c.notes);
    }
}

#[test]
fn a_present_presentmon_followed_no_further_than_its_call_has_no_fate() {
    let head = "Application,ProcessID,SwapChainAddress,Runtime,SyncInterval,PresentFlags,Dropped,TimeInSeconds,MsInPresentAPI,MsBetweenPresents,AllowsTearing,PresentMode,MsUntilRenderComplete,MsUntilDisplayed,MsBetweenDisplayChange";
    let row = |t: f64, dropped: &str, mode: &str, complete: f64, until: f64| {
        format!("dwm.exe,1,0x1,DXGI,1,0,{dropped},{t},0.2,16.7,0,{mode},{complete},{until},0\n")
    };
    let text = format!(
        "{head}\n{}{}{}{}",
        // Untracked: mode unknown, dropped, no completion, no display.
        row(1.0, "1", "Other", 0.0, 0.0),
        // A mode unknown but a completion seen: dropped is a fate.
        row(1.0167, "1", "Other", 2.0, 0.0),
        // A known mode, dropped: a fate.
        row(1.0333, "1", "Hardware: Legacy Flip", 0.0, 0.0),
        row(1.05, "0", "Hardware: Legacy Flip", 1.0, 16.0),
    );
    let c = Capture::parse("t.csv", text.as_bytes()).unwrap();
    let known: Vec<bool> = c.presents.iter().map(|p| p.fate_known).collect();
    assert_eq!(known, [false, true, true, true]);
    let notes = c.notes.join("\n");
    assert!(
        notes.contains("1 present(s) of a mode PresentMon could not tell"),
        "{notes}"
    );
    assert!(!notes.contains("`Dropped` of neither"), "{notes}");
}
