#include "phase_curves.h"

#include "tyndall/core/phase_eval.h"
#include "tyndall/techniques/registry.h"

#include <QStringList>

#include <algorithm>

namespace tyndall::studio {

namespace {

// The media view `view` renders (none for -1 or a view whose part does not resolve).
std::vector<std::string> mediaOf(const Project& project, int view) {
    if (view < 0 || view >= int(project.views.size())) return {};
    try {
        return resolvePart(techniqueCatalogue(), project, project.views[std::size_t(view)]).media;
    } catch (const std::exception&) {
        return {};
    }
}

}  // namespace

void LtsdTables::setDirectory(const QString& directory) {
    directory_ = directory;
    entries_.clear();
}

const LtsdTables::Entry& LtsdTables::get(const std::string& phaseType) {
    auto it = entries_.find(phaseType);
    if (it != entries_.end()) return it->second;
    Entry entry;
    try {
        auto table = std::make_shared<const LtsdTable>(
            loadLtsdTable(ltsdTablePath(phaseType, directory_.toStdString()), phaseType));
        entry.errorCurve = std::make_shared<const std::vector<LtsdFitError>>(ltsdFitErrorCurve(*table, kErrorSamples));
        entry.table = std::move(table);
    } catch (const std::exception& e) {
        entry.error = QString::fromStdString(e.what());
    }
    return entries_.emplace(phaseType, std::move(entry)).first->second;
}

LtsdFit ltsdFitOf(const QString& medium, const QString& view, const PhaseFunction& phase, LtsdTables& tables) {
    LtsdFit fit;
    fit.medium = medium;
    fit.view = view;
    fit.g = phase.g;
    const std::string type = toString(phase.kind);
    if (phase.kind != PhaseKind::HenyeyGreenstein) {
        QStringList have;
        for (const std::string& t : ltsdTablePhases(tables.directory().toStdString()))
            have << QString::fromStdString(t);
        fit.message = QString("No LTSD table for %1 (the phase function of medium '%2'); tables exist for: %3")
                          .arg(QString::fromStdString(type), medium, have.isEmpty() ? "none" : have.join(", "));
        if (have.contains(QString::fromStdString(type)))
            fit.message = QString("The LTSD plots evaluate HG only; medium '%1' has a %2 phase function")
                              .arg(medium, QString::fromStdString(type));
        return fit;
    }
    const LtsdTables::Entry& entry = tables.get(type);
    if (!entry.table) {
        fit.message = "Cannot read the LTSD table of hg: " + entry.error;
        return fit;
    }
    fit.table = entry.table;
    fit.errorCurve = entry.errorCurve;
    return fit;
}

std::vector<PhaseCurve> phaseCurves(const Project& project, int view) {
    const std::vector<std::string> own = mediaOf(project, view);
    std::vector<PhaseCurve> curves;
    auto add = [&](const std::string& name, const PhaseFunction& phase) {
        const bool selected = std::find(own.begin(), own.end(), name) != own.end();
        PhaseCurve c{QString::fromStdString(name + " (" + toString(phase.kind) + ")"),
                     [phase](double mu) { return phaseValue(phase, mu); }, selected};
        curves.insert(selected ? curves.begin() : curves.end(), std::move(c));
    };
    for (const HomogeneousMedium& m : project.scene.media)
        add(m.name, m.phase);
    for (const ParticleMedium& m : project.scene.particleMedia)
        add(m.name, m.phase);
    return curves;
}

LtsdFit ltsdFitOfView(const Project& project, int view, LtsdTables& tables) {
    LtsdFit fit;
    if (view < 0 || view >= int(project.views.size())) {
        fit.message = "No view selected.";
        return fit;
    }
    const QString name = QString::fromStdString(project.views[std::size_t(view)].name);
    const std::vector<std::string> own = mediaOf(project, view);
    if (own.empty()) {
        fit.message = "View '" + name + "' has no medium.";
        return fit;
    }
    const PhaseFunction* phase = nullptr;
    for (const HomogeneousMedium& m : project.scene.media)
        if (m.name == own.front()) phase = &m.phase;
    for (const ParticleMedium& m : project.scene.particleMedia)
        if (m.name == own.front()) phase = &m.phase;
    if (!phase) {
        fit.message = "View '" + name + "' names medium '" + QString::fromStdString(own.front()) +
                      "', which the scene does not have.";
        return fit;
    }
    return ltsdFitOf(QString::fromStdString(own.front()), name, *phase, tables);
}

}  // namespace tyndall::studio
