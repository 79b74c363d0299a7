// The writing half of a cook (cook_run.h): which outputs are current, restored or
// copied before anything cooks, then staging, encoding in parallel, finishing in plan
// order, the texture budget and the records of what is on disk.
#include "cook_run.h"
#include "cook_steps.h"

#include "atlas/core/files.h"
#include "atlas/core/option_schema.h"
#include "atlas/core/parallel.h"
#include "atlas/io/writers.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <set>
#include <sstream>

namespace atlas::detail {

namespace {

// Formats whose encoded files the disk cache keeps (costly to encode).
const std::set<std::string> kCachedOutputFormats = {"dds"};

} // namespace

// An output whose key is unchanged and whose files still match needs no value (nothing
// cooks or loads for it); one whose encoded files the disk cache holds is copied from there.
void CookRun::plan_writes() {
    const bool reuse = opt_.write_outputs && opt_.reuse_outputs && !opt_.checked;
    cache_writable_ = bool(opt_.cache_dir);
    if (!g_.file.empty()) protect_.push_back({g_.file, "the graph file"});
    for (const auto& in : result_.inputs) protect_.push_back({in.path, "an input file of the cook (node '" + in.node + "')"});
    if (opt_.write_outputs && !outputs_.empty()) {
        if (opt_.cache_dir) remove_stale_staging(*opt_.cache_dir);
        for (const GraphOutput* o : outputs_) {
            OutputPlan p;
            p.out = o;
            try {
                const detail::OutputPlace place = detail::output_place(opt_.out_dir, *o, opt_.allow_outside_out, protect_);
                p.root = place.root;
                p.rel = place.rel;
            } catch (const std::exception& e) {
                result_.error_output = o->file;
                result_.error_where = o->where.str();
                throw Error(o->where.str() + ": " + e.what());
            }
            p.name = p.rel.generic_string();
            const detail::OutputSpec spec = detail::output_spec(*o, p.name, state_.at(o->node).hash);
            p.spec = spec.spec;
            p.key = spec.key;
            auto& rec = records_[p.root];
            if (!rec) {
                remove_stale_staging(p.root); // what killed cooks left
                rec = std::make_unique<OutputRecords>(p.root);
            }
            if (reuse) {
                const auto earlier = earlier_.by_key.find(p.key.hex());
                if ((p.record = rec->current(p.name, p.key.hex()))) {
                    p.action = OutputPlan::current;
                } else if (earlier != earlier_.by_key.end() && earlier->second.root != p.root &&
                           files_unchanged(earlier->second.root, earlier->second.record.files)) {
                    p.action = OutputPlan::copy;
                    p.earlier = &earlier->second;
                } else if (const OutputRecord* r = rec->on_disk(p.name); r && r->spec == p.spec && !r->value_hash.empty()) {
                    p.same_spec = r;
                } else if (opt_.cache_dir && kCachedOutputFormats.count(o->format) &&
                           std::filesystem::exists(disk_cache::files_entry_path(*opt_.cache_dir, p.key))) {
                    std::string why;
                    p.cached = disk_cache::load_files(*opt_.cache_dir, p.key, &why);
                    // Only the files this output writes: its own name and its sidecars beside it.
                    if (p.cached)
                        for (const auto& [name, bytes] : p.cached->files) {
                            const std::filesystem::path f(name);
                            if (f.parent_path() != p.rel.parent_path() || f.filename().string().rfind(p.rel.filename().string(), 0) != 0) {
                                why = "it holds '" + name + "', not a file of this output";
                                p.cached.reset();
                                break;
                            }
                        }
                    if (p.cached) {
                        p.action = OutputPlan::restore;
                    } else {
                        std::error_code ec;
                        std::filesystem::remove(disk_cache::files_entry_path(*opt_.cache_dir, p.key), ec);
                        warn("disk cache: the encoded files of output '" + o->file + "' (" + disk_cache::files_entry_path(*opt_.cache_dir, p.key).string() +
                             ") are unusable (" + why + "); discarded, the output is written again");
                    }
                }
            }
            plans_.push_back(std::move(p));
        }
        // Only the outputs to write need values.
        targets_.clear();
        for (const auto& p : plans_)
            if (p.action == OutputPlan::write) targets_.emplace_back(p.out->node, p.out->port);
    }
    std::function<void(const std::string&)> mark_writes = [&](const std::string& name) {
        if (!feeds_writes_.insert(name).second) return;
        for (const auto& [port, b] : state_.at(name).node->inputs) mark_writes(b.node);
    };
    for (const auto& t : targets_) mark_writes(t.first);
}

// Outputs are staged in plan order, encoded in parallel (each writer makes its own
// files from a value nothing changes any more, so the bytes do not depend on what
// else runs), then finished in plan order: sizes, hashes, the disk cache, the report.
void CookRun::write() {
    if (!opt_.write_outputs || outputs_.empty()) {
        for (const GraphOutput* o : outputs_) result_.outputs.push_back({o->node, o->port, o->file, o->format, {}, {}, {}, {}});
        return;
    }
    std::vector<PendingWrite> batch;
    batch.reserve(plans_.size());
    // Writers' copies are held together while they run; one the budget refuses
    // beside the others waits for them (the same decisions whatever the thread count).
    auto flush = [&] {
        encode(batch);
        for (PendingWrite& w : batch) finish_write(w);
        batch.clear();
    };
    for (OutputPlan& p : plans_) {
        const GraphOutput* o = p.out;
        OutputReport orep{o->node, o->port, o->file, o->format, {}, {}, {}, {}, {}, 0.0};
        if (p.same_spec && p.same_spec->value_hash == value_hash(o)) {
            // Upstream changed, this port did not: the files already hold it.
            p.action = OutputPlan::current;
            p.record = p.same_spec;
            OutputRecord r = *p.same_spec;
            r.key = p.key.hex();
            rekeyed_.emplace_back(&p, std::move(r));
            progress_step("up to date: " + o->file, "", 0.0, true);
        }
        if (p.action == OutputPlan::current) {
            orep.status = "up to date";
            orep.metrics = p.record->metrics;
            for (const auto& f : p.record->files) orep.files.push_back({p.root / f.path, f.bytes, f.hash});
            result_.outputs.push_back(orep);
            continue;
        }
        PendingWrite w{&p, result_.outputs.size(), nullptr, {}, {}, {}, std::chrono::steady_clock::now(), 0.0, {}};
        result_.outputs.push_back(orep);
        const std::string what = "output '" + o->file + "': the writer's copy of the value";
        if (p.action == OutputPlan::write) {
            // A writer may copy the value (a slice stack, a half-float frame): room for one copy;
            // the DDS encoder holds its channels and blocks besides (cloudscape's modeling.dds
            // peaked 490 MB of RSS over the one copy counted), so two.
            w.scratch = value_bytes(values_.at(o->node)->at(o->port)) * (o->format == "dds" ? 2 : 1);
            bool fits = true;
            try {
                budget_.check(w.scratch, what);
            } catch (const MemoryBudgetError&) {
                fits = false;
            }
            if (!fits) flush(); // the writers before it finish first, then it is checked alone
        }
        std::optional<std::string> failure;
        try {
            opt_.progress.poll();
            auto& st = staging_[p.root];
            if (!st) {
                st = std::make_unique<StagedOutputs>(p.root);
                st->protect(protect_);
            }
            w.stage = st.get();
            if (p.action == OutputPlan::restore || p.action == OutputPlan::copy) {
                // Encoded files already exist: the disk cache's bytes, or the files an
                // earlier cook of the session wrote elsewhere.
                progress_step("writing " + o->file, "", 0.0, false);
                OutputReport& r = result_.outputs[w.report];
                const bool restore = p.action == OutputPlan::restore;
                r.status = restore ? "restored" : "copied";
                r.metrics = restore ? p.cached->metrics : p.earlier->record.metrics;
                if (restore)
                    for (const auto& [name, bytes] : p.cached->files) {
                        w.staged.push_back(st->stage(name));
                        write_file_checked(w.staged.back(), bytes.data(), bytes.size());
                    }
                else
                    for (const auto& f : p.earlier->record.files) {
                        w.staged.push_back(st->stage(f.path));
                        std::filesystem::copy_file(p.earlier->root / f.path, w.staged.back(), std::filesystem::copy_options::overwrite_existing);
                    }
                p.cached.reset();
                w.encode_seconds = seconds_since(w.start);
            } else {
                budget_.check(w.scratch, what);
                w.scratch_held = ledger_.hold(&p, w.scratch);
                w.target = st->stage(p.rel);
            }
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
        if (failure) {
            // Flushed first, so that the report lists the outputs in plan order.
            flush();
            fail_output(w, *failure);
            continue;
        }
        batch.push_back(std::move(w));
    }
    flush();
    check_texture_budget();
    // Everything written: move it into place.
    // Every root's destinations checked and journaled before any file moves.
    for (auto& [root, st] : staging_) st->prepare();
    for (auto& [root, st] : staging_) st->commit();
    record_written();
}

// The batch's writers, up to the cook's jobs at a time.
void CookRun::encode(std::vector<PendingWrite>& batch) {
    std::vector<size_t> todo;
    for (size_t i = 0; i < batch.size(); ++i)
        if (batch[i].plan->action == OutputPlan::write) todo.push_back(i);
    ThreadLimit arena(jobs_);
    arena.run([&] {
        parallel_for_each(todo.size(), 1, [&](size_t k) {
            PendingWrite& w = batch[todo[k]];
            const GraphOutput* o = w.plan->out;
            const auto t0 = std::chrono::steady_clock::now();
            try {
                opt_.progress.poll();
                progress_step("writing " + o->file, "", 0.0, false);
                OutputReport& r = result_.outputs[w.report];
                r.status = "written";
                w.staged = io::write_value(values_.at(o->node)->at(o->port), w.target, o->format, o->options, &r.metrics);
            } catch (...) {
                w.error = std::current_exception();
            }
            w.encode_seconds = seconds_since(t0);
            w.scratch_held.reset();
        });
    });
}

// One output after its writer: what is on disk is what gets reported and recorded.
void CookRun::finish_write(PendingWrite& w) {
    const auto t0 = std::chrono::steady_clock::now();
    OutputPlan& p = *w.plan;
    const GraphOutput* o = p.out;
    OutputReport& orep = result_.outputs[w.report];
    std::optional<std::string> failure;
    if (w.error) {
        try {
            std::rethrow_exception(w.error);
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
    } else {
        try {
            for (const auto& staged : w.staged) {
                std::error_code ec;
                const uint64_t bytes = std::filesystem::file_size(staged, ec);
                if (ec) throw Error("'" + staged.string() + "' was not written: " + ec.message());
                const auto final_path = w.stage->final_path(staged);
                orep.written.push_back(final_path);
                orep.files.push_back({final_path, bytes, file_content_hash(staged).hex()});
            }
            if (p.action == OutputPlan::copy)
                for (size_t k = 0; k < orep.files.size(); ++k)
                    if (orep.files[k].hash != p.earlier->record.files[k].hash)
                        throw Error("'" + (p.earlier->root / p.earlier->record.files[k].path).string() + "', copied from an earlier cook, changed while it was read");
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
    }
    if (failure) {
        fail_output(w, *failure);
        return;
    }
    if (p.action == OutputPlan::write && cache_writable_ && kCachedOutputFormats.count(o->format)) {
        std::vector<std::pair<std::string, std::filesystem::path>> files;
        for (size_t k = 0; k < w.staged.size(); ++k) files.emplace_back(orep.files[k].path.lexically_relative(p.root).generic_string(), w.staged[k]);
        try {
            disk_cache::store_files(*opt_.cache_dir, p.key, files, orep.metrics);
        } catch (const std::exception& e) {
            cache_writable_ = false;
            warn("disk cache: cannot store the encoded files of output '" + o->file + "' (" + e.what() + "); cooking on without writing the cache");
        }
    }
    orep.seconds = w.encode_seconds + seconds_since(t0);
    written_.push_back({w.report, &p, w.stage, std::move(w.staged)});
    progress_step("wrote " + o->file, "", 0.0, true);
}

// The output failed, not the node that fed it: the report marks the output. With
// keep going, the cook goes on without it; else nothing is written and the
// report ends at this output.
void CookRun::fail_output(PendingWrite& w, const std::string& msg) {
    const GraphOutput* o = w.plan->out;
    OutputReport& orep = result_.outputs[w.report];
    orep.status = "failed";
    orep.error = msg;
    orep.written.clear();
    orep.files.clear();
    orep.seconds = w.encode_seconds;
    if (opt_.keep_going) {
        if (w.stage) w.stage->discard(w.plan->rel);
        warn("output '" + o->file + "' (" + o->where.str() + ") was not written (keep going): " + msg);
        return;
    }
    result_.outputs.resize(w.report + 1);
    result_.error_output = o->file;
    result_.error_where = o->where.str();
    throw Error(detail::output_error(*o, msg));
}

// Content hash of the value an output writes, once per node port.
const std::string& CookRun::value_hash(const GraphOutput* o) {
    auto [it, fresh] = value_hashes_.try_emplace({o->node, o->port});
    if (fresh) it->second = disk_cache::content_hash(values_.at(o->node)->at(o->port)).hex();
    return it->second;
}

// The graph's texture budget, on what is staged or already up to date, before anything moves.
void CookRun::check_texture_budget() {
    if (!g_.texture_budget_mb) return;
    const uint64_t texture_total = result_.texture_bytes();
    const double limit = *g_.texture_budget_mb * 1e6;
    if (double(texture_total) <= limit) return;
    std::vector<std::pair<uint64_t, std::string>> textures;
    for (const OutputReport& o : result_.outputs)
        if (const uint64_t b = o.texture_bytes()) textures.emplace_back(b, o.file);
    std::sort(textures.rbegin(), textures.rend());
    auto mb = [](double bytes) {
        std::ostringstream os;
        os.precision(3);
        os << bytes / 1e6 << " MB";
        return os.str();
    };
    std::string list;
    for (const auto& [b, file] : textures) list += (list.empty() ? "" : ", ") + file + " " + mb(double(b));
    result_.error_where = g_.budget_where.str();
    throw Error(g_.budget_where.str() + ": budget: the textures take " + mb(double(texture_total)) + ", over texture_mb " +
                detail::number_text(*g_.texture_budget_mb) + " by " + mb(double(texture_total) - limit) + " (largest first: " + list +
                "); nothing was written");
}

// Records what is on disk now (renames keep the mtime).
void CookRun::record_written() {
    for (auto& [plan, rec] : rekeyed_) records_.at(plan->root)->set(plan->name, std::move(rec));
    for (const auto& w : written_) {
        OutputRecord rec;
        rec.key = w.plan->key.hex();
        rec.spec = w.plan->spec;
        if (w.plan->action == OutputPlan::write) rec.value_hash = value_hash(w.plan->out);
        if (w.plan->action == OutputPlan::copy) rec.value_hash = w.plan->earlier->record.value_hash;
        const OutputReport& orep = result_.outputs[w.report];
        rec.metrics = orep.metrics;
        for (const auto& f : orep.files)
            rec.files.push_back({f.path.lexically_relative(w.plan->root).generic_string(), f.bytes, file_mtime_ns(f.path), f.hash});
        records_.at(w.plan->root)->set(w.plan->name, std::move(rec));
    }
    // What this cook leaves on disk, for the next cook of the session (issue 43 item 6).
    EarlierOutputs now;
    for (const OutputPlan& p : plans_)
        if (const OutputRecord* r = records_.at(p.root)->find(p.name); r && r->key == p.key.hex() && !r->files.empty())
            now.by_key[r->key] = {p.root, *r};
    earlier_ = std::move(now);
    for (auto& [root, rec] : records_) {
        try {
            rec->save();
        } catch (const std::exception& e) {
            warn("cannot record the outputs written in '" + root.string() + "' (" + e.what() + "); the next cook writes them again");
        }
    }
}

} // namespace atlas::detail
