#include "parameter_panel.h"

#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QSlider>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QVBoxLayout>
#include <QStandardItemModel>

#include <algorithm>
#include <cmath>
#include <memory>

namespace tyndall::studio {

namespace {

constexpr int kSliderSteps = 1000;

// Slider position <-> value, logarithmic where the parameter says so (and its range is positive).
double sliderToValue(const ParamInfo& p, int position) {
    const double t = double(position) / kSliderSteps;
    if (p.logScale && p.min > 0.0) return p.min * std::pow(p.max / p.min, t);
    return p.min + t * (p.max - p.min);
}

int valueToSlider(const ParamInfo& p, double value) {
    double t = 0.0;
    if (p.logScale && p.min > 0.0 && value > 0.0)
        t = std::log(value / p.min) / std::log(p.max / p.min);
    else if (p.max > p.min)
        t = (value - p.min) / (p.max - p.min);
    return int(std::lround(std::clamp(t, 0.0, 1.0) * kSliderSteps));
}

}  // namespace

ParameterPanel::ParameterPanel(Session& session, QWidget* parent) : QWidget(parent), session_(session) {
    form_ = new QFormLayout(this);
    connect(&session_, &Session::viewChanged, this, [this](int view) {
        if (view == view_) refresh();
    });
    connect(&session_, &Session::projectReplaced, this, [this] { showView(session_.project().views.empty() ? -1 : 0); });
    connect(&session_, &Session::sceneChanged, this, [this] { refresh(); });
}

void ParameterPanel::showView(int view) {
    view_ = view;
    // From the views list or a new project: rebuilt at once. From an edit of this panel (a technique change rebuilds
    // the window's views): from the event loop, since the editor is still on the stack.
    if (updating_)
        scheduleRebuild();
    else
        rebuild();
}

std::optional<ParamSet> ParameterPanel::parameters(std::string& key) const {
    const Project& project = session_.project();
    if (view_ < 0 || view_ >= int(project.views.size())) {
        key = "none";
        return std::nullopt;
    }
    const View& view = project.views[std::size_t(view_)];
    key = std::to_string(view_) + "/" + view.name + "/" + view.technique;
    try {
        ParamSet params = makeViewJob(project, session_.path().toStdString(), view.name).request.params;
        for (const ParamInfo& info : params.infos())
            key += "/" + info.name + ":" + std::to_string(int(info.type));
        return params;
    } catch (const std::exception& e) {
        key += std::string("/error:") + e.what();
        return std::nullopt;
    }
}

void ParameterPanel::scheduleRebuild() {
    // Queued: the widget whose signal led here may still be on the stack (a spin box in its stepBy).
    if (rebuildQueued_) return;
    rebuildQueued_ = true;
    QMetaObject::invokeMethod(this, [this] {
        if (!rebuildQueued_) return;  // rebuilt in the meantime
        rebuild();
    }, Qt::QueuedConnection);
}

void ParameterPanel::refresh() {
    // An edit from this panel: its widget shows the value already (and is left alone while the user types in it).
    if (updating_ || rebuildQueued_) return;
    std::string key;
    const std::optional<ParamSet> params = parameters(key);
    if (key != builtKey_ || !params) {
        scheduleRebuild();
        return;
    }
    updating_ = true;
    for (const auto& show : refreshers_)
        show(session_.project().views[std::size_t(view_)], *params);
    updating_ = false;
}

void ParameterPanel::rebuild() {
    while (form_->rowCount() > 0)
        form_->removeRow(0);
    refreshers_.clear();
    rebuildQueued_ = false;
    std::string key;
    const std::optional<ParamSet> parsed = parameters(key);
    builtKey_ = key;
    const Project& project = session_.project();
    if (view_ < 0 || view_ >= int(project.views.size())) return;
    const View& view = project.views[std::size_t(view_)];
    form_->addRow(new QLabel("<b>" + QString::fromStdString(view.name) + "</b>  (" +
                             QString::fromStdString(view.technique) + ")"));

    // The technique: those that cannot render the view's part are disabled, with the reason.
    auto* technique = new QComboBox;
    technique->setObjectName("technique");
    auto* model = qobject_cast<QStandardItemModel*>(technique->model());
    for (const std::string& name : techniqueNames()) {
        technique->addItem(QString::fromStdString(name));
        if (!view.part) continue;  // the default part is what the technique supports
        std::vector<std::string> missing;
        try {
            missing = createTechnique(name)->unsupported(view.part->apply(project.scene));
        } catch (const std::exception& e) {
            missing = {e.what()};
        }
        if (missing.empty()) continue;
        QString why = "cannot render this view's part:";
        for (const std::string& m : missing) why += "\n" + QString::fromStdString(m);
        QStandardItem* item = model->item(technique->count() - 1);
        item->setEnabled(false);
        item->setToolTip(why);
    }
    technique->setCurrentText(QString::fromStdString(view.technique));
    technique->setToolTip("The view's technique (undoable; its parameters start from the defaults)");
    connect(technique, &QComboBox::currentTextChanged, this, [this](const QString& name) {
        if (updating_) return;
        QString error;
        // The panel rebuilds from the event loop after the edit (this combo box is still on the stack).
        updating_ = true;
        const bool ok = session_.setTechnique(view_, name.toStdString(), &error);
        updating_ = false;
        if (!ok) {
            scheduleRebuild();
            emit techniqueRefused(error);
        }
    });
    form_->addRow("technique", technique);

    // What the view renders: every light and medium of the scene, those the technique cannot render disabled with
    // the reason.
    {
        const std::unique_ptr<Technique> t = createTechnique(view.technique);
        std::vector<std::pair<std::string, Support>> elements;
        const Scene& scene = project.scene;
        for (const auto& l : scene.pointLights) elements.push_back({l.name, t->supports(l)});
        for (const auto& l : scene.directionalLights) elements.push_back({l.name, t->supports(l)});
        for (const auto& l : scene.areaLights) elements.push_back({l.name, t->supports(l)});
        const std::size_t lightCount = elements.size();
        for (const auto& m : scene.media) elements.push_back({m.name, t->supports(m)});
        for (const auto& m : scene.particleMedia) elements.push_back({m.name, t->supports(m)});
        auto* box = new QWidget;
        auto* layout = new QVBoxLayout(box);
        layout->setContentsMargins(0, 0, 0, 0);
        std::vector<std::pair<QCheckBox*, bool>> checks;  // and whether it is a light
        for (std::size_t i = 0; i < elements.size(); ++i) {
            const auto& [name, support] = elements[i];
            auto* check = new QCheckBox(QString::fromStdString(name) + (i < lightCount ? "  (light)" : "  (medium)"));
            check->setObjectName("part:" + QString::fromStdString(name));
            check->setEnabled(support.supported);
            check->setToolTip(support.supported ? QString("Rendered by this view when checked")
                                                : "The technique cannot render it: " +
                                                      QString::fromStdString(support.reason));
            layout->addWidget(check);
            checks.push_back({check, i < lightCount});
        }
        auto show = [checks](const View& v, const Project& p) {
            ScenePart part;
            try {
                part = resolvePart(techniqueCatalogue(), p, v);
            } catch (const std::exception&) {
            }
            for (const auto& [check, light] : checks) {
                const std::vector<std::string>& names = light ? part.lights : part.media;
                const std::string name = check->objectName().mid(5).toStdString();
                const QSignalBlocker block(check);
                check->setChecked(std::find(names.begin(), names.end(), name) != names.end());
            }
        };
        show(view, project);
        refreshers_.push_back([this, show](const View& v, const ParamSet&) { show(v, session_.project()); });
        for (const auto& [check, light] : checks)
            connect(check, &QCheckBox::toggled, this, [this, checks](bool) {
                if (updating_) return;
                ScenePart part;
                for (const auto& [c, isLight] : checks)
                    if (c->isChecked()) (isLight ? part.lights : part.media).push_back(c->objectName().mid(5).toStdString());
                QString error;
                updating_ = true;
                const bool ok = session_.setViewPart(view_, part, &error);
                updating_ = false;
                if (!ok) {
                    scheduleRebuild();  // back to the project's part
                    emit techniqueRefused(error);
                }
            });
        form_->addRow("renders", box);
    }

    auto* exposure = new QDoubleSpinBox;
    exposure->setKeyboardTracking(false);  // a typed value is one edit, on Enter or focus-out; arrows stay live
    exposure->setObjectName("exposure");
    exposure->setRange(-20.0, 20.0);
    exposure->setSingleStep(0.5);
    exposure->setSuffix(" EV");
    exposure->setValue(view.exposure);
    exposure->setToolTip("This view's own exposure, saved with the project: for display, PNG export and PSNR. The "
                         "display exposure offset (E / Shift+E, in the status bar) is added to every view on screen");
    connect(exposure, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        if (updating_) return;
        updating_ = true;
        session_.setExposure(view_, v);
        updating_ = false;
    });
    refreshers_.push_back([exposure](const View& v, const ParamSet&) {
        const QSignalBlocker block(exposure);
        exposure->setValue(v.exposure);
    });
    form_->addRow("view exposure", exposure);

    if (!parsed) {
        auto* error = new QLabel(QString::fromStdString(key.substr(key.find("/error:") + 7)));
        error->setWordWrap(true);
        form_->addRow(error);
        return;
    }
    const ParamSet& params = *parsed;
    updating_ = true;
    const int viewIndex = view_;
    for (const ParamInfo& info : params.infos()) {
        const QString name = QString::fromStdString(info.name);
        const QString tip = QString::fromStdString(info.doc + (info.unit.empty() ? "" : " [" + info.unit + "]"));
        const ParamValue& value = params.get(info.name);
        QWidget* editor = nullptr;
        auto set = [this, viewIndex, name = info.name](const nlohmann::json& v) {
            if (updating_) return;
            updating_ = true;
            session_.setParameter(viewIndex, name, v);
            updating_ = false;
        };
        switch (info.type) {
        case ParamType::Float: {
            auto* row = new QWidget;
            auto* layout = new QHBoxLayout(row);
            layout->setContentsMargins(0, 0, 0, 0);
            auto* spin = new QDoubleSpinBox;
            spin->setKeyboardTracking(false);
            spin->setDecimals(info.logScale ? 8 : 4);
            spin->setRange(info.min, info.max);
            spin->setSingleStep((info.max - info.min) / 100.0);
            spin->setValue(std::get<double>(value));
            auto* slider = new QSlider(Qt::Horizontal);
            slider->setRange(0, kSliderSteps);
            slider->setValue(valueToSlider(info, std::get<double>(value)));
            connect(slider, &QSlider::valueChanged, spin, [spin, info](int p) { spin->setValue(sliderToValue(info, p)); });
            connect(spin, &QDoubleSpinBox::valueChanged, this, [set, slider, info](double v) {
                const QSignalBlocker block(slider);
                slider->setValue(valueToSlider(info, v));
                set(v);
            });
            refreshers_.push_back([spin, slider, info](const View&, const ParamSet& p) {
                const double v = std::get<double>(p.get(info.name));
                const QSignalBlocker blockSpin(spin), blockSlider(slider);
                spin->setValue(v);
                slider->setValue(valueToSlider(info, v));
            });
            spin->setObjectName("param:" + name);
            layout->addWidget(slider, 2);
            layout->addWidget(spin, 1);
            editor = row;
            break;
        }
        case ParamType::Int: {
            auto* spin = new QSpinBox;
            spin->setKeyboardTracking(false);
            spin->setRange(int(info.min), int(info.max));
            spin->setValue(int(std::get<std::int64_t>(value)));
            connect(spin, &QSpinBox::valueChanged, this, [set](int v) { set(std::int64_t(v)); });
            refreshers_.push_back([spin, key = info.name](const View&, const ParamSet& p) {
                const QSignalBlocker block(spin);
                spin->setValue(int(std::get<std::int64_t>(p.get(key))));
            });
            spin->setObjectName("param:" + name);
            editor = spin;
            break;
        }
        case ParamType::Bool: {
            auto* check = new QCheckBox;
            check->setChecked(std::get<bool>(value));
            connect(check, &QCheckBox::toggled, this, [set](bool v) { set(v); });
            refreshers_.push_back([check, key = info.name](const View&, const ParamSet& p) {
                const QSignalBlocker block(check);
                check->setChecked(std::get<bool>(p.get(key)));
            });
            check->setObjectName("param:" + name);
            editor = check;
            break;
        }
        case ParamType::Enum: {
            auto* combo = new QComboBox;
            for (const std::string& e : info.enumValues)
                combo->addItem(QString::fromStdString(e));
            combo->setCurrentText(QString::fromStdString(std::get<std::string>(value)));
            connect(combo, &QComboBox::currentTextChanged, this,
                    [set](const QString& v) { set(v.toStdString()); });
            refreshers_.push_back([combo, key = info.name](const View&, const ParamSet& p) {
                const QSignalBlocker block(combo);
                combo->setCurrentText(QString::fromStdString(std::get<std::string>(p.get(key))));
            });
            combo->setObjectName("param:" + name);
            editor = combo;
            break;
        }
        case ParamType::Rgb: {
            auto* row = new QWidget;
            auto* layout = new QHBoxLayout(row);
            layout->setContentsMargins(0, 0, 0, 0);
            const Rgb rgb = std::get<Rgb>(value);
            std::array<QDoubleSpinBox*, 3> spins{};
            for (int c = 0; c < 3; ++c) {
                spins[std::size_t(c)] = new QDoubleSpinBox;
                spins[std::size_t(c)]->setKeyboardTracking(false);
                spins[std::size_t(c)]->setRange(info.min, info.max);
                spins[std::size_t(c)]->setDecimals(4);
                spins[std::size_t(c)]->setValue(rgb[c]);
                layout->addWidget(spins[std::size_t(c)]);
            }
            for (QDoubleSpinBox* s : spins)
                connect(s, &QDoubleSpinBox::valueChanged, this, [set, spins](double) {
                    set(nlohmann::json::array({spins[0]->value(), spins[1]->value(), spins[2]->value()}));
                });
            refreshers_.push_back([spins, key = info.name](const View&, const ParamSet& p) {
                const Rgb v = std::get<Rgb>(p.get(key));
                for (int c = 0; c < 3; ++c) {
                    const QSignalBlocker block(spins[std::size_t(c)]);
                    spins[std::size_t(c)]->setValue(v[c]);
                }
            });
            row->setObjectName("param:" + name);
            editor = row;
            break;
        }
        }
        editor->setToolTip(tip);
        auto* label = new QLabel(name);
        label->setToolTip(tip);
        form_->addRow(label, editor);
    }
    updating_ = false;
}

}  // namespace tyndall::studio
