#include "parameter_panel.h"

#include "tyndall/render.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QSlider>
#include <QSpinBox>

#include <cmath>

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
        if (view == view_ && !updating_) rebuild();
    });
    connect(&session_, &Session::projectReplaced, this, [this] { showView(session_.project().views.empty() ? -1 : 0); });
    connect(&session_, &Session::sceneChanged, this, [this] {
        if (!updating_) rebuild();
    });
}

void ParameterPanel::showView(int view) {
    view_ = view;
    rebuild();
}

void ParameterPanel::rebuild() {
    while (form_->rowCount() > 0)
        form_->removeRow(0);
    const Project& project = session_.project();
    if (view_ < 0 || view_ >= int(project.views.size())) return;
    const View& view = project.views[std::size_t(view_)];
    form_->addRow(new QLabel("<b>" + QString::fromStdString(view.name) + "</b>  (" +
                             QString::fromStdString(view.technique) + ")"));

    auto* exposure = new QDoubleSpinBox;
    exposure->setObjectName("exposure");
    exposure->setRange(-20.0, 20.0);
    exposure->setSingleStep(0.5);
    exposure->setSuffix(" EV");
    exposure->setValue(view.exposure);
    exposure->setToolTip("Exposure of this view for display, PNG export and PSNR");
    connect(exposure, &QDoubleSpinBox::valueChanged, this, [this](double v) { session_.setExposure(view_, v); });
    form_->addRow("exposure", exposure);

    ParamSet params;
    try {
        params = makeViewJob(project, session_.path().toStdString(), view.name).request.params;
    } catch (const std::exception& e) {
        auto* error = new QLabel(QString::fromStdString(e.what()));
        error->setWordWrap(true);
        form_->addRow(error);
        return;
    }
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
            spin->setObjectName("param:" + name);
            layout->addWidget(slider, 2);
            layout->addWidget(spin, 1);
            editor = row;
            break;
        }
        case ParamType::Int: {
            auto* spin = new QSpinBox;
            spin->setRange(int(info.min), int(info.max));
            spin->setValue(int(std::get<std::int64_t>(value)));
            connect(spin, &QSpinBox::valueChanged, this, [set](int v) { set(std::int64_t(v)); });
            spin->setObjectName("param:" + name);
            editor = spin;
            break;
        }
        case ParamType::Bool: {
            auto* check = new QCheckBox;
            check->setChecked(std::get<bool>(value));
            connect(check, &QCheckBox::toggled, this, [set](bool v) { set(v); });
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
                spins[std::size_t(c)]->setRange(info.min, info.max);
                spins[std::size_t(c)]->setDecimals(4);
                spins[std::size_t(c)]->setValue(rgb[c]);
                layout->addWidget(spins[std::size_t(c)]);
            }
            for (QDoubleSpinBox* s : spins)
                connect(s, &QDoubleSpinBox::valueChanged, this, [set, spins](double) {
                    set(nlohmann::json::array({spins[0]->value(), spins[1]->value(), spins[2]->value()}));
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
