// The studio's main window: the Vulkan viewport in the centre, the views, parameters and metrics in docks, menus and a
// toolbar. It owns the session (project, undo), the render service and the compositor's state, and re-renders a view
// shortly after each edit of it (debounced) while references refine in the background.
#pragma once

#include "compositor.h"
#include "parameter_panel.h"
#include "render_service.h"
#include "session.h"
#include "viewport.h"

#include <QMainWindow>
#include <QTimer>

#include <set>
#include <vector>

class QListWidget;
class QLabel;
class QVulkanInstance;

namespace tyndall::studio {

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    // `overrides` apply to every project opened (the command line's --set, e.g. a smaller camera for tests).
    MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides = {});
    ~MainWindow() override;

    // Opens a project; on failure keeps the current one and, with `dialog`, says why in a message box.
    bool openProject(const QString& path, bool dialog = true);
    // Writes every view, its reference and its difference (EXR and PNG), the viewport (PNG) and the metrics (JSON and
    // CSV) into `folder`. Returns false with the reason.
    bool exportComparison(const QString& folder, QString* error);

    Session& session() { return session_; }
    RenderService& renderService() { return *renderer_; }
    Viewport* viewport() { return viewport_; }
    CompositorState& compositorState() { return state_; }
    const std::vector<ViewFrame>& frames() const { return frames_; }
    // The last frame composed for the viewport.
    const QImage& composedFrame() const { return composed_; }
    // Every view's latest render is final and nothing is queued.
    bool settled() const;

    void setLayoutMode(Layout layout);
    void selectView(int view);
    void recompose();

protected:
    void closeEvent(QCloseEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;

private:
    void buildMenus();
    void rebuildViews();
    void renderView(int view, bool reference);
    void renderAll();
    void onOutput(const RenderOutput& out);
    void onKey(int key, Qt::KeyboardModifiers modifiers, bool pressed);
    void updateTitle();
    void updateMetricsDock();
    bool confirmDiscard();

    Session session_;
    std::vector<std::string> overrides_;
    RenderService* renderer_ = nullptr;
    Viewport* viewport_ = nullptr;
    ParameterPanel* parameters_ = nullptr;
    QListWidget* viewList_ = nullptr;
    QLabel* metrics_ = nullptr;
    CompositorState state_;
    std::vector<ViewFrame> frames_;
    std::vector<quint64> generation_, referenceGeneration_;
    std::vector<bool> pending_;   // a technique render of the view is queued or running
    std::set<int> dirtyViews_;    // edited views waiting for the debounce
    QTimer debounce_;
    QImage composed_;
    quint64 nextGeneration_ = 1;
};

}  // namespace tyndall::studio
