fn main() {
    let frames: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(20);
    let cfg = dhcd::experiment::Config { frames, ..Default::default() };
    let t = std::time::Instant::now();
    let r = dhcd::experiment::run(&cfg, &mut |p, d, _| eprintln!("{:?} {} {} {:.2}", p, d, std::time::Instant::now().duration_since(t).as_secs_f64(), 0)).unwrap();
    eprintln!("wall {:?} sim {:.2} meas {:.2} cal {:.2}", t.elapsed(), r.simulate_s, r.measure_s, r.calibrate_s);
    for m in &r.methods {
        let c = m.totals();
        eprintln!("{} {:?} time {:.1}ms upd {:.1} query {:.1} pred {:.1} fixed {:.1} err {:.3} errfix {:.3} cv {:.2} cp {:.2} cu {:.2}", m.method, c, m.total_time_ns()/1e6, m.total_update_ns()/1e6, m.total_query_ns()/1e6, m.total_predicted_ns()/1e6, m.fixed_ns()/1e6, m.model_error(), m.model_with_fixed_error(), m.costs.c_v.median, m.costs.c_p.median, m.costs.c_u.median);
    }
    for (s, st) in r.methods[0].steps.iter().enumerate() { if s % 5 == 0 { eprintln!("{s} {:?}", st.counters); } }
}
